//! English questions, question CSVs, LLM replies and source arguments.

use proptest::collection::vec;
use proptest::prelude::*;
use proptest::sample::select;
use proptest::test_runner::TestRunner;

use super::logic::query_text;
use super::{sample, vocab, wild_count, wild_num};

// ----------------------------------------------------------------- questions

const GRAMMAR_WORDS: &[&str] = &[
    "is", "are", "there", "a", "an", "the", "any", "does", "do", "how", "many", "which", "what",
    "who", "that", "and", "or", "not", "no", "every", "all", "each", "of", "to", "from", "on",
    "in", "at", "with", "than", "it", "its", "than", "more", "other", "another", "one", "two", "?",
    ",", "'s", "first", "then", "while", "between", "both", "neither", "nor", "only",
];

/// English questions from the LogicPad's phrases and the grammar's words.
pub fn question(runner: &mut TestRunner) -> Vec<u8> {
    let phrases: Vec<String> = vocab().phrases.clone();
    let word = prop_oneof![
        3 => select(phrases),
        3 => select(GRAMMAR_WORDS).prop_map(str::to_string),
        1 => wild_num(),
        1 => "[a-z]{1,10}",
    ];
    let q = (
        select(
            &[
                "Is there", "Does", "How many", "Are all", "Is the", "Which", "Do", "",
            ][..],
        ),
        vec(word, 0..16),
        select(&["?", "", "??", " ?", "."][..]),
    )
        .prop_map(|(start, words, end)| format!("{start} {}{end}", words.join(" ")));
    sample(q, runner).into_bytes()
}

/// CSV files of questions, with quoting and odd columns.
pub fn question_csv(runner: &mut TestRunner) -> Vec<u8> {
    let header = select(
        &[
            "Question",
            "Id,Question",
            "Question,Query",
            "question",
            "\"Question\"",
            "Q",
        ][..],
    );
    let cell = prop_oneof![
        3 => select(&["Is there a white car?", "How many pedestrians are there?", "Does the van move?"][..])
            .prop_map(str::to_string),
        1 => "[a-z ,\"]{0,20}",
        1 => Just("\"a \"\"quoted\"\" one, with comma\"".to_string()),
        1 => Just("\"unterminated".to_string()),
    ];
    let rows = vec(vec(cell, 1..3).prop_map(|c| c.join(",")), 0..8);
    let csv = (header, rows, select(&["\n", "\r\n"][..]))
        .prop_map(|(h, rows, nl)| format!("{h}{nl}{}", rows.join(nl)));
    sample(csv, runner).into_bytes()
}

/// A language model's replies: a query wrapped in fences, labels, quotes.
pub fn llm_reply(runner: &mut TestRunner) -> Vec<u8> {
    let reply = (
        select(
            &[
                "",
                "Yes",
                "No",
                "The answer is yes.",
                "```\n",
                "Query: ",
                "`",
                "\"",
                "\n\n",
            ][..],
        ),
        query_text(),
        select(&["", "\n```", "`", "\"", " — because it moves", "\nCANNOT: x"][..]),
    )
        .prop_map(|(a, q, b)| format!("{a}{q}{b}"));
    sample(reply, runner).into_bytes()
}

/// Source arguments.
pub fn source_spec(runner: &mut TestRunner) -> Vec<u8> {
    let spec = (
        select(
            &[
                "sim", "kitti", "json", "facts", "frames", "", "SIM", "sim:sim",
            ][..],
        ),
        select(&[":", "", "::"][..]),
        select(
            &[
                "urban_crossing",
                "../x",
                "",
                "/dev/zero",
                "a@b",
                "x y",
                "0-9",
                "ünï",
            ][..],
        ),
        proptest::option::of(wild_count()),
    )
        .prop_map(|(k, c, r, seed)| match seed {
            Some(s) => format!("{k}{c}{r}@{s}"),
            None => format!("{k}{c}{r}"),
        });
    let range = (
        wild_count(),
        select(&["-", "--", " - ", ""][..]),
        wild_count(),
    )
        .prop_map(|(a, d, b)| format!("{a}{d}{b}"));
    sample(prop_oneof![spec, range], runner).into_bytes()
}
