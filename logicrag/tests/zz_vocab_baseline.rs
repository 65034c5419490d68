//! TEMPORARY: dumps translations for a before/after comparison. Not for commit.
use logicrag::translate::{Translator, Vocabulary};
use std::collections::BTreeSet;
use std::path::PathBuf;

fn questions() -> Vec<String> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut qs = BTreeSet::new();
    let tsv = std::fs::read_to_string(root.join("tests/data/fresh_questions.tsv")).unwrap();
    for l in tsv.lines().filter(|l| !l.starts_with('#')) {
        if let Some(q) = l.split('\t').nth(1) { qs.insert(q.to_string()); }
    }
    for f in ["../../shared/data/logicrag-reference/kitti_translations_gold.csv", "../../shared/data/logicrag-reference/kitti_questions.csv"] {
        let t = std::fs::read_to_string(root.join(f)).unwrap();
        for l in t.lines() { for part in l.split(',') { if part.ends_with('?') { qs.insert(part.trim_matches('"').to_string()); } } }
    }
    let mut files = vec![];
    for d in ["src/translate", "src/translate/parser", "tests"] {
        if let Ok(rd) = std::fs::read_dir(root.join(d)) { for e in rd { let p = e.unwrap().path(); if p.extension().is_some_and(|x| x == "rs") { files.push(p); } } }
    }
    for p in files {
        let t = std::fs::read_to_string(&p).unwrap();
        let mut rest = t.as_str();
        while let Some(i) = rest.find('"') {
            rest = &rest[i + 1..];
            let Some(j) = rest.find('"') else { break };
            let s = &rest[..j];
            if s.len() > 3 && s.ends_with('?') && s.chars().next().is_some_and(|c| c.is_ascii_uppercase()) && !s.contains('\\') { qs.insert(s.to_string()); }
            rest = &rest[j + 1..];
        }
    }
    qs.into_iter().collect()
}

fn dump(t: &Translator, tag: &str, qs: &[String]) {
    let mut out = String::new();
    for q in qs {
        match t.translate(q) {
            Ok(tr) => out.push_str(&format!("{q}\n  = {}\n  notes {:?}\n", tr.query, tr.notes)),
            Err(e) => out.push_str(&format!("{q}\n  ! {e}\n")),
        }
    }
    let mut sk = t.skipped_phrases().to_vec(); sk.sort();
    out.push_str(&format!("SKIPPED {sk:#?}\n"));
    let dir = std::env::var("VB_DIR").unwrap_or("/tmp/vb".into());
    std::fs::write(format!("{dir}/{tag}.txt"), out).unwrap();
}

#[test]
fn dump_all() {
    let qs = questions();
    println!("{} questions", qs.len());
    dump(&Translator::builtin(), "builtin", &qs);
    let pad = logicpad::LogicPad::builtin();
    dump(&Translator::new(Vocabulary::from_schema(pad.schema()).unwrap()), "logicpad", &qs);
    let r = logicpad::LogicPad::load("../../shared/data/logicrag-reference/LogicPad.yaml").unwrap();
    dump(&Translator::new(Vocabulary::from_schema(r.schema()).unwrap()), "reference", &qs);
}
