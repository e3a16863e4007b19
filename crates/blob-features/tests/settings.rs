//! The settings checks: every number that would silently change the output is refused by
//! name, and the defaults pass.

use blob_features::{BlobConfig, BlobCorrespondences, BlobError, MatchConfig, UnknownPolicy};

#[test]
fn default_settings_pass() {
    assert_eq!(BlobConfig::default().validate(), Ok(()));
    assert_eq!(MatchConfig::default().validate(), Ok(()));
    assert!(BlobCorrespondences::new(BlobConfig::default(), MatchConfig::default()).is_ok());
}

#[test]
fn nan_round_ratio_is_refused_by_name() {
    let config = BlobConfig {
        round_ratio: f64::NAN,
        ..BlobConfig::default()
    };
    let err = config.validate().unwrap_err();
    assert!(
        matches!(err, BlobError::Setting { name: "round_ratio", value, rule: "a number (not NaN)" } if value.is_nan()),
        "{err:?}"
    );
    assert_eq!(
        err.to_string(),
        "invalid blob setting `round_ratio` = NaN: must be a number (not NaN)"
    );
}

#[test]
fn nan_drop_fraction_is_refused() {
    let config = BlobConfig {
        unknown: UnknownPolicy::Drop(f64::NAN),
        ..BlobConfig::default()
    };
    assert!(matches!(
        config.validate(),
        Err(BlobError::Setting {
            name: "unknown",
            ..
        })
    ));
    // Any number is a bar: above 1 keeps every blob.
    let keep_all = BlobConfig {
        unknown: UnknownPolicy::Drop(2.0),
        ..BlobConfig::default()
    };
    assert_eq!(keep_all.validate(), Ok(()));
}

#[test]
fn negative_or_nan_matching_bars_are_refused() {
    // Each bar at each refused value, the other at its default.
    let with = |name: &str, value: f64| {
        let mut c = MatchConfig::default();
        *match name {
            "ratio" => &mut c.ratio,
            _ => &mut c.max_distance,
        } = value;
        c
    };
    for (name, config) in [
        ("ratio", with("ratio", -0.8)),
        ("ratio", with("ratio", f64::NAN)),
        ("max_distance", with("max_distance", -0.3)),
        ("max_distance", with("max_distance", f64::NAN)),
    ] {
        let err = BlobCorrespondences::new(BlobConfig::default(), config).unwrap_err();
        assert!(
            matches!(err, BlobError::Setting { name: n, rule: "0 or more", .. } if n == name),
            "{name}: {err:?}"
        );
    }
    // An infinite bar switches its test off.
    let open = MatchConfig {
        ratio: f64::INFINITY,
        max_distance: f64::INFINITY,
        ..MatchConfig::default()
    };
    assert_eq!(open.validate(), Ok(()));
}
