//! The mutation engine: byte-level edits (bit flips, inserted, deleted and
//! duplicated ranges, splices of two inputs) and token-level ones that know
//! what hurts a text parser (a number replaced by an extreme one, a line
//! repeated thousands of times, brackets, quotes and `==>` inserted, nesting
//! thousands deep).
//!
//! There is no coverage feedback on stable Rust, so the edits are chosen to
//! reach the edges a parser's author forgets: the extremes of numbers, the
//! sizes where quadratic work shows, the characters that open a nested
//! construct, text that is not UTF-8.

use crate::rng::Rng;

/// The largest input a mutation may produce: large enough for a line
/// repeated 10,000 times, small enough that one input never dominates a run.
pub const MAX_MUTATED_LEN: usize = 4 * 1024 * 1024;

/// Numbers at the edges: overflow of u32/i64/u64/f64, NaN and infinities
/// in the spellings Rust, YAML and JSON readers accept or half-accept,
/// subnormals, negative zero, signs and bases a reader may not expect.
pub const EXTREME_NUMBERS: &[&str] = &[
    "0",
    "-0",
    "-1",
    "1e300",
    "-1e300",
    "1e309",
    "-1e309",
    "1e-320",
    "NaN",
    "nan",
    "-nan",
    ".nan",
    "inf",
    "-inf",
    ".inf",
    "-.inf",
    "infinity",
    "4294967295",
    "4294967296",
    "-4294967296",
    "2147483648",
    "-2147483649",
    "9223372036854775807",
    "9223372036854775808",
    "-9223372036854775809",
    "18446744073709551615",
    "18446744073709551616",
    "340282366920938463463374607431768211456",
    "1000000001",
    "99999999999999999999999999999999999999",
    "0x7fffffff",
    "0o777",
    "1_000_000",
    "+5",
    "5.",
    ".5",
    "-.5e3",
    "1e",
    "1e+",
    "0.1e-999999",
    "1e999999999999",
    "65536",
    "256",
    "255",
    "100000",
    "1000000",
];

/// Fragments that open, close or separate something in one of the formats.
const TOKENS: &[&str] = &[
    "(",
    ")",
    "[",
    "]",
    "{",
    "}",
    "\"",
    "'",
    "`",
    "==>",
    "=>",
    "->",
    "→",
    "∀x:",
    "∃y.",
    "¬",
    "^",
    "∧",
    "∨",
    "|",
    "&",
    "!=",
    "≠",
    "=",
    ",",
    ":",
    ": ",
    "- ",
    "-",
    ".",
    "?",
    "?x",
    "\t",
    "\n",
    "\r\n",
    "\r",
    " ",
    "#",
    "%",
    "---\n",
    "...\n",
    "&a ",
    "*a",
    "!!str ",
    "!!binary ",
    "<<: ",
    "~",
    "null",
    "true",
    "\\",
    "\\u0000",
    "\\uD800",
    "\u{feff}",
    "\0",
    "\u{202e}",
    "e\u{301}",
    "\u{10ffff}",
    "𝔸",
    "x",
    "car_1",
    "Vehicles(x)",
    "TypeOf(x) = Car",
    "forall",
    "not",
    "and",
    "P2:",
    "DontCare",
    "Car",
    "frames:",
    "name:",
    "agents:",
    "\t\t",
];

/// Bytes that are never valid UTF-8 or that readers special-case.
const BAD_BYTES: &[&[u8]] = &[
    b"\xff",
    b"\xfe",
    b"\xc3\x28",
    b"\xe2\x82",
    b"\xf0\x9f\x92",
    b"\xed\xa0\x80",
    b"\xc0\x80",
    b"\x00",
    b"\x7f",
    b"\x1b[2J",
];

/// Applies 1 to 8 random mutations to `base`; `others` are the inputs a
/// splice may take its second half from (the target's corpus).
pub fn mutate(base: &[u8], others: &[&[u8]], rng: &mut Rng) -> Vec<u8> {
    let mut data = base.to_vec();
    // Mostly one or two edits (they keep the input close to something the
    // parser accepts, so its deeper code runs), sometimes a pile of them.
    let rounds = match rng.below(10) {
        0..=4 => 1,
        5..=7 => 2,
        _ => 3 + rng.below(6),
    };
    for _ in 0..rounds {
        mutate_once(&mut data, others, rng);
        if data.len() > MAX_MUTATED_LEN {
            data.truncate(MAX_MUTATED_LEN);
        }
    }
    data
}

fn mutate_once(data: &mut Vec<u8>, others: &[&[u8]], rng: &mut Rng) {
    match rng.below(18) {
        0 => flip_bit(data, rng),
        1 => set_byte(data, rng),
        2 => insert_random_bytes(data, rng),
        3 => delete_range(data, rng),
        4 => duplicate_range(data, rng),
        5 => splice(data, others, rng),
        6..=8 => replace_number(data, rng),
        9 => repeat_line(data, rng),
        10 | 11 => insert_token(data, rng),
        12 => swap_lines(data, rng),
        13 => delete_line(data, rng),
        14 => truncate(data, rng),
        15 => replace_word(data, others, rng),
        16 => nest(data, rng),
        _ => insert_bad_bytes(data, rng),
    }
}

/// A random byte offset in `0..=len`.
fn offset(data: &[u8], rng: &mut Rng) -> usize {
    rng.below(data.len() + 1)
}

/// A random range `a..b` inside `data`, at most `max` long.
fn range(data: &[u8], rng: &mut Rng, max: usize) -> (usize, usize) {
    let a = offset(data, rng);
    let b = (a + rng.below(max + 1)).min(data.len());
    (a, b)
}

fn flip_bit(data: &mut [u8], rng: &mut Rng) {
    if data.is_empty() {
        return;
    }
    let i = rng.below(data.len());
    let bit = rng.below(8);
    if let Some(b) = data.get_mut(i) {
        *b ^= 1 << bit;
    }
}

fn set_byte(data: &mut Vec<u8>, rng: &mut Rng) {
    const INTERESTING: &[u8] = b"\x00\xff\x7f\x80\n\r\t\"'\\(){}[]:,-#0 9.";
    if data.is_empty() {
        data.push(INTERESTING[rng.below(INTERESTING.len())]);
        return;
    }
    let i = rng.below(data.len());
    data[i] = INTERESTING[rng.below(INTERESTING.len())];
}

fn insert_random_bytes(data: &mut Vec<u8>, rng: &mut Rng) {
    let at = offset(data, rng);
    let n = 1 + rng.below(16);
    let bytes: Vec<u8> = (0..n).map(|_| (rng.next_u64() & 0xff) as u8).collect();
    data.splice(at..at, bytes);
}

fn delete_range(data: &mut Vec<u8>, rng: &mut Rng) {
    let (a, b) = range(data, rng, 64);
    data.drain(a..b);
}

fn duplicate_range(data: &mut Vec<u8>, rng: &mut Rng) {
    let (a, b) = range(data, rng, 256);
    let copy = data[a..b].to_vec();
    let times = *rng.pick(&[1usize, 2, 8, 64]).unwrap_or(&1);
    let at = offset(data, rng);
    let mut ins = Vec::with_capacity(copy.len() * times);
    for _ in 0..times {
        ins.extend_from_slice(&copy);
    }
    data.splice(at..at, ins);
}

/// The first part of this input followed by the last part of another: the
/// classic cross-over, which keeps both halves' syntax.
fn splice(data: &mut Vec<u8>, others: &[&[u8]], rng: &mut Rng) {
    let Some(other) = rng.pick(others) else {
        return;
    };
    let cut = offset(data, rng);
    let from = rng.below(other.len() + 1);
    data.truncate(cut);
    data.extend_from_slice(&other[from..]);
}

/// Byte ranges of the numbers in `data` (digits with sign, point, exponent).
fn numbers(data: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < data.len() {
        let starts_number = data[i].is_ascii_digit()
            || (matches!(data[i], b'-' | b'+' | b'.')
                && data.get(i + 1).is_some_and(u8::is_ascii_digit));
        if !starts_number {
            i += 1;
            continue;
        }
        let start = i;
        i += 1;
        while i < data.len()
            && (data[i].is_ascii_digit()
                || matches!(data[i], b'.' | b'e' | b'E')
                || (matches!(data[i], b'-' | b'+') && matches!(data[i - 1], b'e' | b'E')))
        {
            i += 1;
        }
        out.push((start, i));
    }
    out
}

fn replace_number(data: &mut Vec<u8>, rng: &mut Rng) {
    let nums = numbers(data);
    let repl = *rng.pick(EXTREME_NUMBERS).unwrap_or(&"NaN");
    match rng.pick(&nums) {
        Some(&(a, b)) => {
            data.splice(a..b, repl.bytes());
        }
        None => {
            let at = offset(data, rng);
            data.splice(at..at, repl.bytes());
        }
    }
}

/// Byte ranges of the lines of `data`, each with its newline.
fn lines(data: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    for (i, b) in data.iter().enumerate() {
        if *b == b'\n' {
            out.push((start, i + 1));
            start = i + 1;
        }
    }
    if start < data.len() {
        out.push((start, data.len()));
    }
    out
}

/// One line repeated up to 10,000 times: the shape of "2,000 objects in one
/// frame" or "a list of 10,000 rules", where quadratic work shows.
fn repeat_line(data: &mut Vec<u8>, rng: &mut Rng) {
    let ls = lines(data);
    let Some(&(a, b)) = rng.pick(&ls) else {
        return;
    };
    let mut line = data[a..b].to_vec();
    if line.last() != Some(&b'\n') {
        line.push(b'\n');
    }
    let times = *rng.pick(&[2usize, 10, 100, 1000, 10_000]).unwrap_or(&2);
    let room = MAX_MUTATED_LEN.saturating_sub(data.len()) / line.len().max(1);
    let times = times.min(room);
    let mut ins = Vec::with_capacity(line.len() * times);
    for _ in 0..times {
        ins.extend_from_slice(&line);
    }
    data.splice(b..b, ins);
}

fn insert_token(data: &mut Vec<u8>, rng: &mut Rng) {
    let tok = *rng.pick(TOKENS).unwrap_or(&"(");
    let at = offset(data, rng);
    data.splice(at..at, tok.bytes());
}

fn swap_lines(data: &mut Vec<u8>, rng: &mut Rng) {
    let ls = lines(data);
    if ls.len() < 2 {
        return;
    }
    let i = rng.below(ls.len());
    let j = rng.below(ls.len());
    let (x, y) = (ls[i.min(j)], ls[i.max(j)]);
    if x == y {
        return;
    }
    let mut out = Vec::with_capacity(data.len());
    out.extend_from_slice(&data[..x.0]);
    out.extend_from_slice(&data[y.0..y.1]);
    out.extend_from_slice(&data[x.1..y.0]);
    out.extend_from_slice(&data[x.0..x.1]);
    out.extend_from_slice(&data[y.1..]);
    *data = out;
}

fn delete_line(data: &mut Vec<u8>, rng: &mut Rng) {
    let ls = lines(data);
    if let Some(&(a, b)) = rng.pick(&ls) {
        data.drain(a..b);
    }
}

fn truncate(data: &mut Vec<u8>, rng: &mut Rng) {
    let at = offset(data, rng);
    data.truncate(at);
}

/// Byte ranges of identifier-like words.
fn words(data: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < data.len() {
        if data[i].is_ascii_alphabetic() || data[i] == b'_' {
            let start = i;
            while i < data.len() && (data[i].is_ascii_alphanumeric() || data[i] == b'_') {
                i += 1;
            }
            out.push((start, i));
        } else {
            i += 1;
        }
    }
    out
}

/// A word replaced by a word of this or another input: a predicate name
/// where a constant was, a YAML key where a value was.
fn replace_word(data: &mut Vec<u8>, others: &[&[u8]], rng: &mut Rng) {
    let here = words(data);
    let Some(&(a, b)) = rng.pick(&here) else {
        return;
    };
    let source: &[u8] = match rng.pick(others) {
        Some(o) if rng.chance(50) => o,
        _ => data,
    };
    let there = words(source);
    let Some(&(c, d)) = rng.pick(&there) else {
        return;
    };
    let word = source[c..d].to_vec();
    data.splice(a..b, word);
}

/// Nesting hundreds or thousands deep: recursive-descent parsers and
/// recursive data types overflow their stack here.
fn nest(data: &mut Vec<u8>, rng: &mut Rng) {
    let (open, close) = *rng
        .pick(&[
            ("(", ")"),
            ("[", "]"),
            ("{", "}"),
            ("¬", ""),
            ("- ", ""),
            ("[{\"a\":", "}]"),
            ("∃x:", ""),
            ("((", ")"),
        ])
        .unwrap_or(&("(", ")"));
    let depth = *rng.pick(&[50usize, 300, 3000, 30_000]).unwrap_or(&50);
    let closed = rng.chance(60);
    let at = offset(data, rng);
    let mut ins = open.repeat(depth).into_bytes();
    let tail = if closed {
        close.repeat(depth).into_bytes()
    } else {
        Vec::new()
    };
    // Wrap a piece of the input so the innermost level is something real.
    let end = (at + rng.below(32)).min(data.len());
    let middle = data[at..end].to_vec();
    ins.extend_from_slice(&middle);
    ins.extend_from_slice(&tail);
    data.splice(at..end, ins);
}

fn insert_bad_bytes(data: &mut Vec<u8>, rng: &mut Rng) {
    let bytes = *rng.pick(BAD_BYTES).unwrap_or(&&b"\xff"[..]);
    let at = offset(data, rng);
    data.splice(at..at, bytes.iter().copied());
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mutations_are_deterministic_and_bounded() {
        let base = b"Vehicles(car_1)\nColorOf(car_1, White)\nframes: 60\n".to_vec();
        let other = b"P2: 721.5 0 609.6 44.9 0 721.5 172.9 0.2 0 0 1 0.003\n".to_vec();
        let others: Vec<&[u8]> = vec![&other];
        for i in 0..2000 {
            let a = mutate(&base, &others, &mut Rng::for_input(3, "t", i));
            let b = mutate(&base, &others, &mut Rng::for_input(3, "t", i));
            assert_eq!(a, b);
            assert!(a.len() <= MAX_MUTATED_LEN);
        }
        // Empty inputs are fine too.
        for i in 0..200 {
            let _ = mutate(b"", &[], &mut Rng::new(i));
        }
    }

    #[test]
    fn numbers_and_words_are_found() {
        assert_eq!(numbers(b"a 12 -3.5e-2 x"), vec![(2, 4), (5, 12)]);
        assert_eq!(words(b"Foo(x_1, 2)"), vec![(0, 3), (4, 7)]);
        assert_eq!(lines(b"a\nb"), vec![(0, 2), (2, 3)]);
    }
}
