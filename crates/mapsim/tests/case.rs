//! Properties of generated cases not covered by simulator.rs: config validation, exactness of
//! `map_to_world`, and a proptest over the `strategies` module.

use grid_core::metrics::agreement;
use grid_core::{CellState, DVec2, Rigid2, wrap_angle};
use mapsim::strategies::{PairParams, Worlds, case};
use mapsim::{CaseConfig, Error, generate_case};
use proptest::prelude::*;

fn close(a: &Rigid2, b: &Rigid2, tol: f64) -> bool {
    wrap_angle(a.theta - b.theta).abs() < tol
        && (a.tx - b.tx).abs() < tol
        && (a.ty - b.ty).abs() < tol
}

#[test]
fn invalid_configs_are_errors_not_panics() {
    let mut c = CaseConfig::paper();
    c.robots.truncate(1);
    assert!(matches!(generate_case(&c, 1), Err(Error::Config(_))));
    let mut c = CaseConfig::paper();
    c.robots[0].failed_beams = vec![16];
    assert!(matches!(generate_case(&c, 1), Err(Error::Config(_))));
    let mut c = CaseConfig::paper();
    c.overlap = 1.5;
    assert!(matches!(generate_case(&c, 1), Err(Error::Config(_))));
    let mut c = CaseConfig::paper();
    c.world.width = 3;
    assert!(matches!(generate_case(&c, 1), Err(Error::WorldSize { .. })));
}

/// Every occupied cell of a noise-free map lands, through `map_to_world`, on or next to an
/// obstacle of the world: the pose is exact, not merely close.
#[test]
fn occupied_cells_land_on_world_obstacles() {
    let mut c = CaseConfig::paper();
    for r in &mut c.robots {
        r.noise_bound = 0.0;
    }
    let case = generate_case(&c, 3).unwrap();
    for r in &case.robots {
        let (mut n, mut near) = (0, 0);
        for y in 0..r.map.height() {
            for x in 0..r.map.width() {
                if r.map.state(x, y) == CellState::Occupied {
                    n += 1;
                    let w = r.map_to_world.apply(DVec2::new(x as f64, y as f64));
                    let (wx, wy) = (w.x.round() as i64, w.y.round() as i64);
                    if (-1..=1)
                        .any(|dy| (-1..=1).any(|dx| case.world.is_occupied(wx + dx, wy + dy)))
                    {
                        near += 1;
                    }
                }
            }
        }
        assert!(n > 50, "only {n} occupied cells");
        assert_eq!(near, n, "occupied cells away from any obstacle");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 6, ..ProptestConfig::default() })]

    /// truth(i, j) o truth(j, i) is the identity, and truth(0, 1) carries robot 1's path, seen in
    /// map 1, onto the same path seen in map 0.
    #[test]
    fn truth_is_consistent(c in case(PairParams { size: 150..=220, worlds: Worlds::Both, ..PairParams::default() })) {
        let t01 = c.truth(0, 1);
        let t10 = c.truth(1, 0);
        prop_assert!(close(&t01.compose(&t10), &Rigid2::IDENTITY, 1e-9));
        let p1 = c.robots[1].path_in_map();
        let inv0 = c.robots[0].map_to_world.inverse();
        for (k, p) in p1.iter().enumerate().step_by(7) {
            let in0 = inv0.apply(c.robots[1].path[k]);
            prop_assert!((t01.apply(*p) - in0).length() < 1e-9);
        }
        let ag = agreement(&c.robots[0].map, &c.robots[1].map, &t01);
        if c.achieved_overlap > 0.2 {
            prop_assert!(ag.acceptance_index().unwrap_or(0.0) > 0.8, "{ag:?}");
        }
    }
}
