use super::super::lexer::tokenize;
use super::super::{Translator, Vocabulary};
use super::*;

fn lexicon() -> Lexicon {
    Lexicon::new(&Vocabulary::builtin())
}

fn kinds(q: &str) -> Vec<String> {
    let lex = lexicon();
    let toks = tokenize(q);
    items(&lex, &toks)
        .into_iter()
        .map(|it| match it.kind {
            ItemKind::Content(e) => format!("<{}>", e.sense.target()),
            ItemKind::Closed(c) => format!("{c:?}"),
            ItemKind::Constant => "Constant".to_string(),
            ItemKind::Unknown => "?".to_string(),
        })
        .collect()
}

/// The built-in translator's query for `q`, or the error as text.
pub(super) fn query(q: &str) -> String {
    Translator::builtin()
        .translate(q)
        .map(|t| t.query)
        .unwrap_or_else(|e| format!("ERROR {e}"))
}

#[test]
fn items_take_the_longest_phrase() {
    assert_eq!(kinds("police car"), ["<PoliceCar>"]);
    assert_eq!(kinds("stop sign"), ["<StopSign>"]);
    assert_eq!(kinds("traffic sign"), ["<TrafficSign>"]);
    assert_eq!(kinds("stop"), ["<Stopped>"]);
    assert_eq!(kinds("enter the scene"), ["<Appear>"]);
    assert_eq!(kinds("trafficlights"), ["<TrafficLight>"]);
    assert_eq!(kinds("the far left"), ["Det(Plain)", "<FarLeft>"]);
    assert_eq!(
        kinds("near the left"),
        ["Prep(Near)", "Det(Plain)", "<Left>"]
    );
    assert_eq!(kinds("zzz"), ["?"]);
}

#[test]
fn variables_are_named_in_order_of_appearance() {
    assert_eq!(var_name(0), "x");
    assert_eq!(var_name(2), "z");
    assert_eq!(var_name(6), "x1");
    assert_eq!(
        query("Does the van get closer to the truck that approaches the bus?"),
        "TypeOf(x, Van)^TypeOf(y, Truck)^TypeOf(z, Bus)^GettingCloser(y, z)^GettingCloser(x, y)"
    );
}
