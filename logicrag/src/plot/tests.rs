use super::*;

#[test]
fn only_png_and_svg_are_written() {
    assert_eq!(Format::of(Path::new("a/b.PNG")).ok(), Some(Format::Png));
    assert_eq!(Format::of(Path::new("b.svg")).ok(), Some(Format::Svg));
    assert!(matches!(
        Format::of(Path::new("b.jpg")),
        Err(PlotError::Format { .. })
    ));
    assert!(matches!(
        Format::of(Path::new("noext")),
        Err(PlotError::Format { .. })
    ));
}

#[test]
fn accuracy_against_noise_renders_one_line_per_scenario() {
    let dir = std::env::temp_dir().join(format!("logicrag-noise-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let line = |name: &str, acc: [f64; 3]| NoiseLine {
        scenario: name.into(),
        // Out of order on purpose: the chart orders the levels.
        points: vec![
            ("high".into(), acc[2]),
            ("none".into(), acc[0]),
            ("default".into(), acc[1]),
        ],
    };
    let lines = [
        line("braking", [1.0, 0.977, 0.958]),
        line("pickup", [1.0, 1.0, 0.992]),
    ];
    let svg = dir.join("noise.svg");
    noise_chart(&lines, "accuracy against noise", &svg, (800, 500)).expect("svg");
    let text = std::fs::read_to_string(&svg).expect("svg text");
    for word in [
        "braking",
        "pickup",
        "none",
        "default",
        "high",
        "noise level",
    ] {
        assert!(text.contains(word), "the SVG lacks {word}");
    }
    let png = dir.join("noise.png");
    noise_chart(&lines, "accuracy against noise", &png, (640, 400)).expect("png");
    let img = image::open(&png).expect("png reads").to_rgb8();
    assert_eq!((img.width(), img.height()), (640, 400));
    assert!(img.pixels().filter(|p| p.0 != [255, 255, 255]).count() > 2000);
    assert!(matches!(
        noise_chart(&[], "t", &png, (640, 400)),
        Err(PlotError::Empty(_))
    ));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_bundled_font_registers() {
    assert!(register_font().is_ok());
}

#[test]
fn a_reliability_diagram_names_its_curves() {
    let dir = std::env::temp_dir().join(format!("logicrag-rel-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let bin = |from: f64, n: usize, p: f64, f: f64| crate::eval::ReliabilityBin {
        from,
        to: from + 0.1,
        n,
        mean_p_yes: p,
        frequency_yes: f,
    };
    let curves = [ReliabilityCurve {
        label: "high".into(),
        bins: vec![
            bin(0.0, 400, 0.01, 0.02),
            bin(0.5, 3, 0.55, 0.33),
            bin(0.9, 380, 0.99, 0.97),
        ],
    }];
    let svg = dir.join("rel.svg");
    reliability_chart(&curves, "reliability", &svg, (700, 700)).expect("svg");
    let text = std::fs::read_to_string(&svg).expect("svg text");
    for word in [
        "high",
        "perfectly calibrated",
        "observed frequency of yes",
        "answers",
    ] {
        assert!(text.contains(word), "the SVG lacks {word}");
    }
    let empty = [ReliabilityCurve {
        label: "x".into(),
        bins: vec![],
    }];
    assert!(matches!(
        reliability_chart(&empty, "t", &svg, (700, 700)),
        Err(PlotError::Empty(_))
    ));
    let _ = std::fs::remove_dir_all(&dir);
}
