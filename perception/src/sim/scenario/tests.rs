use super::*;

fn err(edit: impl FnOnce(&mut Scenario)) -> String {
    let mut s = Scenario::builtin("urban_crossing").unwrap();
    edit(&mut s);
    s.validate().unwrap_err().to_string()
}

#[test]
fn a_scenario_too_long_or_too_crowded_is_an_error_naming_the_file_and_limit() {
    // Regression: `frames: 1000000` (within MAX_FRAMES) took 3.4 GB and
    // aborted; 2,000 agents took 113 s and 4.3 GB.
    let e = Scenario::from_yaml("name: x\nframes: 1000000\nego: {speed: 1}\n", "long.yaml")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("long.yaml:")
            && e.contains("`frames` 1000000 × (0 objects + the ego) = 1000000 object-frames")
            && e.contains("limit of 500000")
            && e.contains("MAX_SCENARIO_OBJECT_FRAMES"),
        "{e}"
    );
    // The whole budget for the ego alone is accepted.
    let at_budget = format!("name: x\nframes: {MAX_SCENARIO_OBJECT_FRAMES}\nego: {{speed: 1}}\n");
    Scenario::from_yaml(&at_budget, "ok.yaml").unwrap();
    let agents: String = (1..=2000)
        .map(|id| {
            format!(
                "  - {{id: {id}, class: Vehicles, type: Car, start: [4, {id}], parked: true}}\n"
            )
        })
        .collect();
    let yaml = format!("name: x\nframes: 10\nego: {{speed: 1}}\nagents:\n{agents}");
    let e = Scenario::from_json(
        &serde_json::to_string(&serde_saphyr::from_str::<Scenario>(&yaml).unwrap()).unwrap(),
        "crowd.json",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("crowd.json:")
            && e.contains("2000 objects (2000 agents, 0 roads × 3 with their sidewalks, 0 props)")
            && e.contains("limit of 256 objects per scenario"),
        "{e}"
    );
    // `validate` on a scenario built in code says the same.
    let e = err(|s| s.frames = 400_000);
    assert!(
        e.contains("urban_crossing") && e.contains("object-frames exceed"),
        "{e}"
    );
}

#[test]
fn builtins_validate() {
    for name in BUILTIN_NAMES {
        Scenario::builtin(name).unwrap();
    }
}

#[test]
fn non_finite_and_out_of_range_numbers_are_rejected() {
    let e = err(|s| {
        s.ego.phases = vec![Phase {
            from: 0,
            to: 1,
            accel: Some(f64::NAN),
            speed_to: None,
            turn_deg: None,
            enter: None,
            merge_into: None,
        }]
    });
    assert!(e.contains("ego: phase 0..1 `accel` and `turn_deg`"), "{e}");
    let e = err(|s| {
        s.ego.phases = vec![Phase {
            from: 0,
            to: 1,
            accel: None,
            speed_to: None,
            turn_deg: Some(f64::INFINITY),
            enter: None,
            merge_into: None,
        }]
    });
    assert!(e.contains("`turn_deg` must be finite"), "{e}");
    let e = err(|s| s.agents[0].size = Some([1.5, 0.0, 4.0]));
    assert!(e.contains("`size` must be three positive numbers"), "{e}");
    let e = err(|s| {
        s.world.props.push(PropSpec {
            class: ObjectClass::Pole,
            at: [f64::NAN, 3.0],
            size: None,
            heading_deg: 0.0,
            color: None,
        })
    });
    assert!(e.contains("world.props["), "{e}");
    let e = err(|s| s.world.roads[0].center = [0.0, f64::NAN]);
    assert!(e.contains("finite centre"), "{e}");
    let e = err(|s| s.view.min_depth_m = 0.0);
    assert!(e.contains("0 < min_depth_m < max_depth_m"), "{e}");
    let e = err(|s| s.view.max_depth_m = f64::NAN);
    assert!(e.contains("0 < min_depth_m < max_depth_m"), "{e}");
    let e = err(|s| {
        s.noise = Some(NoiseSpec {
            miss_probability: 1.5,
            ..NoiseSpec::default()
        })
    });
    assert!(e.contains("probabilities in [0, 1]"), "{e}");
    let e = err(|s| {
        s.noise = Some(NoiseSpec {
            box_jitter_px: -1.0,
            ..NoiseSpec::default()
        })
    });
    assert!(e.contains("non-negative sigmas"), "{e}");
    // Regression: `name: ../../x` made `simulate --out` write outside DIR.
    for name in ["../../x", "a/b", "", ".hidden"] {
        let e = err(|s| s.name = name.into());
        assert!(e.contains("it names files"), "{name}: {e}");
    }
}

#[test]
fn a_noise_level_is_a_preset_optionally_with_its_sigmas_scaled() {
    let plain: NoiseLevel = "high".parse().unwrap();
    assert_eq!(plain, NoisePreset::High.into());
    assert_eq!(plain.to_string(), "high");
    assert_eq!(plain.spec(), NoisePreset::High.spec());
    let double: NoiseLevel = "high*2".parse().unwrap();
    assert_eq!((double.preset(), double.scale()), (NoisePreset::High, 2.0));
    assert_eq!(double.to_string(), "high*2");
    let (h, d) = (NoisePreset::High.spec().unwrap(), double.spec().unwrap());
    assert_eq!(d.position_sigma_m, 2.0 * h.position_sigma_m);
    assert_eq!(d.depth_sigma_fraction, 2.0 * h.depth_sigma_fraction);
    assert_eq!(d.box_jitter_px, 2.0 * h.box_jitter_px);
    // Rates are not spreads: misses and id switches stay.
    assert_eq!(d.miss_probability, h.miss_probability);
    assert_eq!(d.id_switch_probability, h.id_switch_probability);
    let mono: NoiseLevel = "mono*1.5".parse().unwrap();
    assert_eq!(mono.to_string(), "mono*1.5");
    let (m, s) = (NoisePreset::Mono.spec().unwrap(), mono.spec().unwrap());
    assert_eq!(s.depth_sigma_per_m, 1.5 * m.depth_sigma_per_m);
    assert_eq!(s.depth_bias_fraction, 1.5 * m.depth_bias_fraction);
    // The text round-trips.
    assert_eq!(mono.to_string().parse::<NoiseLevel>().unwrap(), mono);
    assert_eq!(
        "none*1".parse::<NoiseLevel>().unwrap(),
        NoisePreset::None.into()
    );
}

#[test]
fn a_bad_noise_factor_is_refused_with_a_message() {
    for bad in [
        "high*0", "high*-1", "high*", "high*x", "high*inf", "high*NaN", "high*2*2",
    ] {
        let e = bad.parse::<NoiseLevel>().unwrap_err();
        assert!(matches!(e, NoiseLevelError::BadFactor(_)), "{bad}: {e}");
        let m = e.to_string();
        assert!(
            m.contains(bad) && m.contains("positive finite number"),
            "{m}"
        );
    }
    let e = "loud*2".parse::<NoiseLevel>().unwrap_err();
    assert!(e.to_string().contains("unknown noise level `loud`"), "{e}");
    assert!(e.to_string().contains("high, mono"), "{e}");
    let e = "none*2".parse::<NoiseLevel>().unwrap_err();
    assert!(matches!(e, NoiseLevelError::ScaledNone(_)), "{e}");
    assert!(NoiseLevel::new(NoisePreset::High, f64::INFINITY).is_err());
}
