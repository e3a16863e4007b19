//! Maps nobody would hand in on purpose, generated: a cell to a few dozen across, all one
//! value, all unknown, a single wall, a thin strip, random speckle, a bare room. The
//! registration must decline them or answer with a finite transform, never panic, and say why
//! it declined. (The binary refuses an all-unknown map before registering it; the library
//! must not rely on that.)

use grid_core::{OccupancyGrid, Pose2};
use mapmerge::{RegisterConfig, register};
use proptest::prelude::*;

/// An unknown cell (free cells are 0, occupied 100).
const UNKNOWN: u8 = grid_core::UNKNOWN;

#[derive(Debug, Clone)]
enum Pattern {
    /// Every cell the same value.
    Uniform(u8),
    /// Free with a single wall row (or column when `vertical`) at `at` modulo the size.
    Wall { at: usize, vertical: bool },
    /// Each cell unknown, free or occupied with the given weights.
    Speckle {
        unknown: u32,
        free: u32,
        occupied: u32,
        seed: u64,
    },
    /// A walled room with wall segments inside, each `(x, y, length, vertical)` taken modulo
    /// the size: the one kind here a registration can place.
    Room(Vec<(usize, usize, usize, bool)>),
}

fn pattern() -> impl Strategy<Value = Pattern> {
    prop_oneof![
        prop_oneof![Just(UNKNOWN), Just(0u8), Just(100u8)].prop_map(Pattern::Uniform),
        (any::<usize>(), any::<bool>()).prop_map(|(at, vertical)| Pattern::Wall { at, vertical }),
        (0u32..5, 0u32..5, 0u32..5, any::<u64>()).prop_map(|(unknown, free, occupied, seed)| {
            Pattern::Speckle {
                unknown,
                free: free + 1,
                occupied,
                seed,
            }
        }),
        prop::collection::vec(
            (any::<usize>(), any::<usize>(), 3usize..40, any::<bool>()),
            0..6
        )
        .prop_map(Pattern::Room),
    ]
}

fn grid(width: usize, height: usize, pattern: &Pattern) -> OccupancyGrid {
    let cells: Vec<u8> = (0..width * height)
        .map(|i| {
            let (x, y) = (i % width, i / width);
            match *pattern {
                Pattern::Uniform(v) => v,
                Pattern::Wall { at, vertical } => {
                    let on = if vertical {
                        x == at % width
                    } else {
                        y == at % height
                    };
                    if on { 100 } else { 0 }
                }
                Pattern::Speckle {
                    unknown,
                    free,
                    occupied,
                    seed,
                } => {
                    // A small hash of the cell and the seed: deterministic speckle.
                    let h = (i as u64 ^ seed)
                        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
                        .rotate_left(29);
                    let r = (h % u64::from(unknown + free + occupied)) as u32;
                    if r < unknown {
                        UNKNOWN
                    } else if r < unknown + free {
                        0
                    } else {
                        100
                    }
                }
                Pattern::Room(ref segments) => {
                    let border = x == 0 || y == 0 || x + 1 == width || y + 1 == height;
                    let inside = segments.iter().any(|&(sx, sy, len, vertical)| {
                        let (sx, sy) = (sx % width, sy % height);
                        if vertical {
                            x == sx && y >= sy && y < sy + len
                        } else {
                            y == sy && x >= sx && x < sx + len
                        }
                    });
                    if border || inside { 100 } else { 0 }
                }
            }
        })
        .collect();
    OccupancyGrid::from_cells(width, height, 0.05, Pose2::default(), cells).unwrap()
}

/// A map up to `max` cells on a side.
fn map(max: usize) -> impl Strategy<Value = OccupancyGrid> {
    (1..max, 1..max, pattern()).prop_map(|(w, h, p)| grid(w, h, &p))
}

/// `name` from the environment, if set to a number.
fn env_number(name: &str) -> Option<u64> {
    std::env::var(name).ok().and_then(|s| s.trim().parse().ok())
}

proptest! {
    // As in `properties.rs`: a fixed seed, so a red run reproduces; `MAPMERGE_PROPTEST_SEED=N`
    // and `PROPTEST_CASES=N` explore more.
    #![proptest_config(ProptestConfig {
        cases: env_number("PROPTEST_CASES").map_or(48, |n| n.min(u64::from(u32::MAX)) as u32),
        rng_seed: proptest::test_runner::RngSeed::Fixed(
            env_number("MAPMERGE_PROPTEST_SEED").unwrap_or(11),
        ),
        ..ProptestConfig::default()
    })]

    #[test]
    fn degenerate_maps_are_declined_or_answered_finitely(a in map(48), b in map(48)) {
        let r = register(&a, &b, &RegisterConfig::default()).unwrap();
        match &r.accepted {
            Some(c) => {
                let t = c.transform;
                prop_assert!(t.theta.is_finite() && t.tx.is_finite() && t.ty.is_finite(), "{t:?}");
                prop_assert!(r.reason.is_none());
            }
            None => prop_assert!(r.reason.is_some(), "declined without a reason"),
        }
    }

    /// A degenerate map against itself, up to 160 cells across (large enough that rooms are
    /// registered): declined, or found in place within 1 px. About half are answered, so the
    /// bound is tested: 27 of the 48 at the fixed seed, counted with a temporary print on
    /// 2026-12-08, when seeds 1-8 at 200 cases each found no answer out of place.
    #[test]
    fn a_degenerate_map_against_itself_is_declined_or_found_in_place(a in map(160)) {
        let r = register(&a, &a, &RegisterConfig::default()).unwrap();
        if let Some(c) = &r.accepted {
            let t = c.transform;
            let off = grid_core::metrics::displacement_error(&a, &t, &grid_core::Rigid2::IDENTITY);
            prop_assert!(off.is_some_and(|e| e <= 1.0), "{t:?}: {off:?} px off");
        } else {
            prop_assert!(r.reason.is_some(), "declined without a reason");
        }
    }
}
