use super::*;

/// Regression (fuzzer, issue 13): lines, columns and line bounds from
/// the newline index are what searching the text gives, at every offset.
#[test]
fn the_newline_index_agrees_with_a_search() {
    let text = "ab\n∀x : P(x)\r\n\n\rq\u{301}\nlast ∧";
    let src = SourceFile::new("f", text);
    for offset in 0..=text.len() + 2 {
        let off = floor_char_boundary(text, offset);
        let before = &text[..off];
        let line_start = before.rfind('\n').map_or(0, |p| p + 1);
        let want = (
            before.matches('\n').count() + 1,
            before[line_start..].chars().count() + 1,
        );
        assert_eq!(src.line_col(offset), want, "{offset}");
        assert_eq!(src.line_of(off).1, line_start, "{offset}");
        let line_end = text[off..].find('\n').map_or(text.len(), |p| off + p);
        assert_eq!(src.line_end(off), line_end, "{offset}");
    }
}

/// Regression (fuzzer, issue 13): an excerpt reads only the characters
/// it shows, and shows exactly what collecting the whole line showed —
/// cut or not on either side, multi-byte characters, spans that run
/// past the end of their line.
#[test]
fn excerpts_read_only_what_they_show() {
    fn whole_line(d: &Diagnostic) -> String {
        let text = &d.source.text;
        let start = floor_char_boundary(text, d.span.start);
        let end = floor_char_boundary(text, d.span.end.max(d.span.start));
        let line_start = text[..start].rfind('\n').map_or(0, |p| p + 1);
        let line_end = text[start..].find('\n').map_or(text.len(), |p| start + p);
        let before: Vec<char> = text[line_start..start].chars().collect();
        let marked: Vec<char> = text[start..end.min(line_end)].chars().collect();
        let after: Vec<char> = text[end.min(line_end)..line_end].chars().collect();
        let (kb, km, ka) = (
            before.len().min(EXCERPT_CONTEXT),
            marked.len().min(EXCERPT_CONTEXT),
            after.len().min(EXCERPT_CONTEXT),
        );
        let mut shown = String::new();
        if kb < before.len() {
            shown.push('…');
        }
        shown.extend(&before[before.len() - kb..]);
        let caret_col = shown.chars().count();
        shown.extend(&marked[..km]);
        if km < marked.len() {
            shown.push('…');
        }
        shown.extend(&after[..ka]);
        if ka < after.len() {
            shown.push('…');
        }
        let mut out = format!(
            "{}\n    | {shown}\n    | {}{}",
            d.summary(),
            " ".repeat(caret_col),
            "^".repeat(km.max(1))
        );
        out.push_str(" here\n");
        out
    }
    let line = format!("{}Foo(x) ∧ {}Bar(y)", "é".repeat(300), "∨".repeat(59));
    let text = format!("first\n{line}\n{}\nlast", "x".repeat(61));
    let src = SourceFile::new("t", text.as_str());
    let boundaries: Vec<usize> = (0..=text.len())
        .filter(|&i| text.is_char_boundary(i))
        .collect();
    for (k, &start) in boundaries.iter().enumerate() {
        for &end in boundaries[k..].iter().step_by(37).take(6) {
            let d = Diagnostic::new(
                DiagKind::Structure,
                Severity::Error,
                &src,
                Span::new(start, end),
                "m",
            )
            .with_label("here");
            assert_eq!(d.render_excerpt(), whole_line(&d), "{start}..{end}");
        }
    }
}

/// Regression (fuzzer, issue 13): reading a span through the line index
/// gives exactly what miette's full scan gives, for every offset, line
/// ending (`\n`, `\r\n`, a lone `\r`) and amount of context.
#[test]
fn windowed_read_span_matches_a_full_scan() {
    use miette::SourceCode;
    let text = "first line\nsecond\r\nthird\rfourth ∀ line\n\nsixth\nlast";
    let src = SourceFile::new("t", text);
    let d = Diagnostic::new(
        DiagKind::Structure,
        Severity::Error,
        &src,
        Span::new(0, 1),
        "m",
    );
    let boundaries: Vec<usize> = (0..=text.len())
        .filter(|&i| text.is_char_boundary(i))
        .collect();
    for &start in &boundaries {
        for &end in boundaries.iter().filter(|&&e| e >= start).take(4) {
            for (before, after) in [(0, 0), (1, 1), (2, 3), (9, 9)] {
                let span = miette::SourceSpan::new(start.into(), end - start);
                let want = text.read_span(&span, before, after);
                let got = d.read_span(&span, before, after);
                match (want, got) {
                    (Ok(w), Ok(g)) => {
                        let at = format!("{start}..{end} ({before}, {after})");
                        assert_eq!(w.data(), g.data(), "{at}");
                        assert_eq!(w.span(), g.span(), "{at}");
                        assert_eq!(w.line(), g.line(), "{at}");
                        assert_eq!(w.column(), g.column(), "{at}");
                        assert_eq!(w.line_count(), g.line_count(), "{at}");
                    }
                    (Err(_), Err(_)) => {}
                    (w, g) => panic!("{start}..{end}: {:?} vs {:?}", w.is_ok(), g.is_ok()),
                }
            }
        }
    }
}

#[test]
fn line_and_column_count_characters() {
    let src = SourceFile::new("f", "ab\n∀x : P(x)\n");
    assert_eq!(src.line_col(0), (1, 1));
    assert_eq!(src.line_col(3), (2, 1));
    // `x` after the 3-byte `∀` is column 2.
    assert_eq!(src.line_col(6), (2, 2));
    assert_eq!(src.line_col(999), (3, 1));
    // Inside a UTF-8 sequence: moved back to the character.
    assert_eq!(src.line_col(4), (2, 1));
}

#[test]
fn a_diagnostic_on_a_long_line_is_an_excerpt() {
    // Regression: a rule of 10,000 chained `==>` was echoed whole (133 KB).
    let line: String = (0..5_000).map(|i| format!("P{i}(x) ==> ")).collect();
    let text = format!("a: 1\nlogic: \"{line}\"\n");
    let at = text.find("P2500(x)").unwrap();
    let d = Diagnostic::new(
        DiagKind::FolSyntax,
        Severity::Error,
        &SourceFile::new("pad.yaml", text.clone()),
        Span::new(at, at + 8),
        "formula nested too deep",
    )
    .with_label("here");
    let out = d.render_plain(100);
    assert!(out.len() < 600, "{out}");
    assert!(out.starts_with("pad.yaml:2:"), "{out}");
    assert!(
        out.contains("…") && out.contains("P2500(x)") && out.contains("^^^^^^^^ here"),
        "{out}"
    );
    // A short line still gets miette's drawing.
    let short = Diagnostic::new(
        DiagKind::FolSyntax,
        Severity::Error,
        &SourceFile::new("p.yaml", "logic: \"A(x) ==> \"\n"),
        Span::new(7, 11),
        "bad",
    );
    assert!(short.render_plain(100).contains("╭─[p.yaml:1:8]"));
}

/// Regression (fuzzer, issue 13): skipping candidates by length picks
/// exactly what comparing every one did, and a huge name finds nothing.
#[test]
fn the_banded_distance_is_the_distance_up_to_its_bound() {
    let words = [
        "", "a", "ab", "ba", "abc", "Moving", "moving", "Movng", "Mvoing", "Stopped", "ColorOf",
        "ColourOf", "colorof", "TypeOf", "kitten", "sitting", "ÄÖü", "äöu",
    ];
    for a in words {
        for b in words {
            let (ac, bc): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
            let full = strsim::levenshtein(a, b);
            for k in 0..5 {
                let want = (full <= k).then_some(full);
                assert_eq!(bounded_levenshtein(&ac, &bc, k), want, "{a} {b} {k}");
            }
        }
    }
}

#[test]
fn did_you_mean_skips_by_length_without_changing_the_answer() {
    fn every_candidate<'a>(name: &str, cands: &[&'a str]) -> Option<&'a str> {
        let lower = name.to_lowercase();
        let mut best: Option<(usize, &'a str)> = None;
        for &c in cands {
            if c == name {
                continue;
            }
            let d = strsim::levenshtein(&lower, &c.to_lowercase());
            let allowed = (name.chars().count().max(c.chars().count()) / 4).clamp(1, 3);
            if d <= allowed && best.is_none_or(|(bd, bc)| (d, c) < (bd, bc)) {
                best = Some((d, c));
            }
        }
        best.map(|(_, c)| c)
    }
    let cands = [
        "Appears",
        "Trafficsign",
        "Moving",
        "Move",
        "M",
        "TypeOf",
        "İstanbul",
        "ColorOf",
        "SpeedUp",
        "SpeedDown",
        "LeftOf",
        "RightOf",
        "InFrontOf",
        "DistanceDecrease",
    ];
    for name in [
        "Appear",
        "TrafficSign",
        "moving",
        "Mov",
        "Mo",
        "typeof",
        "istanbul",
        "Colour",
        "SpeedUpp",
        "LeftOff",
        "Inront",
        "DistanceDecreas",
        "X",
        "",
        "ΑΒΓ",
    ] {
        assert_eq!(
            did_you_mean(name, cands),
            every_candidate(name, &cands),
            "{name}"
        );
    }
    assert_eq!(did_you_mean(&"a".repeat(1_000_000), cands), None);
}

#[test]
fn did_you_mean_prefers_close_names() {
    let names = ["Appears", "Disappears", "Moving", "Trafficsign"];
    assert_eq!(did_you_mean("Appear", names), Some("Appears"));
    assert_eq!(did_you_mean("TrafficSign", names), Some("Trafficsign"));
    assert_eq!(did_you_mean("Collide", names), None);
}
