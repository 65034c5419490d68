//! Minimal RFC 4180 CSV reading and writing for question files
//! (`Question` column in, `Question,Query` out).

use thiserror::Error;

/// Errors reading a CSV text.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum CsvError {
    /// Occurs when a quoted field is still open at the end of the text.
    #[error("line {line}: quoted field is never closed")]
    UnterminatedQuote {
        /// 1-based line where the field starts.
        line: usize,
    },
    /// Occurs when a quote appears after other characters inside an unquoted
    /// field, or text follows a closing quote.
    #[error("line {line}: stray quote character")]
    StrayQuote {
        /// 1-based line of the quote.
        line: usize,
    },
    /// Occurs when the header row lacks a required column.
    #[error("no '{name}' column in the header (found: {found})")]
    MissingColumn {
        /// The column looked for.
        name: String,
        /// The header's columns, comma-separated.
        found: String,
    },
    /// Occurs when the text has no header row.
    #[error("the CSV text is empty")]
    Empty,
}

/// Parses CSV text into records of fields. Quoted fields may hold commas,
/// doubled quotes and line breaks; `\r\n` and `\n` both end a record; a
/// final empty line is not a record.
///
/// # Errors
/// [`CsvError::UnterminatedQuote`] or [`CsvError::StrayQuote`].
pub fn parse_csv(text: &str) -> Result<Vec<Vec<String>>, CsvError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut records = Vec::new();
    let mut record = Vec::new();
    let mut field = String::new();
    let mut chars = text.chars().peekable();
    let mut line = 1usize;
    let mut quoted = false;
    let mut after_quote = false;
    let mut field_started = false;
    let mut quote_line = 1usize;
    while let Some(c) = chars.next() {
        if quoted {
            match c {
                '"' if chars.peek() == Some(&'"') => {
                    chars.next();
                    field.push('"');
                }
                '"' => {
                    quoted = false;
                    after_quote = true;
                }
                '\n' => {
                    line += 1;
                    field.push(c);
                }
                _ => field.push(c),
            }
            continue;
        }
        match c {
            '"' if !field_started => {
                quoted = true;
                field_started = true;
                quote_line = line;
            }
            '"' => return Err(CsvError::StrayQuote { line }),
            ',' => {
                record.push(std::mem::take(&mut field));
                after_quote = false;
                field_started = false;
            }
            '\r' if chars.peek() == Some(&'\n') => {}
            '\n' => {
                record.push(std::mem::take(&mut field));
                records.push(std::mem::take(&mut record));
                after_quote = false;
                field_started = false;
                line += 1;
            }
            _ if after_quote => return Err(CsvError::StrayQuote { line }),
            _ => {
                field.push(c);
                field_started = true;
            }
        }
    }
    if quoted {
        return Err(CsvError::UnterminatedQuote { line: quote_line });
    }
    if field_started || !record.is_empty() {
        record.push(field);
        records.push(record);
    }
    Ok(records)
}

/// Appends one CSV record to `out`, quoting fields that need it, ending
/// with `\n`.
pub(crate) fn write_record(out: &mut String, fields: &[&str]) {
    for (i, f) in fields.iter().enumerate() {
        if i > 0 {
            out.push(',');
        }
        if f.contains([',', '"', '\n', '\r']) || f.starts_with(' ') || f.ends_with(' ') {
            out.push('"');
            out.push_str(&f.replace('"', "\"\""));
            out.push('"');
        } else {
            out.push_str(f);
        }
    }
    out.push('\n');
}

/// The values of the named column, one per data record (records too short
/// to hold it give an empty string, so row numbers stay aligned).
///
/// # Errors
/// [`CsvError::Empty`] without a header, [`CsvError::MissingColumn`], or a
/// parse error.
pub fn column(text: &str, name: &str) -> Result<Vec<String>, CsvError> {
    let records = parse_csv(text)?;
    let mut it = records.into_iter();
    let header = it.next().ok_or(CsvError::Empty)?;
    let idx = header
        .iter()
        .position(|h| h.trim() == name)
        .ok_or_else(|| CsvError::MissingColumn {
            name: name.to_string(),
            found: header.join(","),
        })?;
    Ok(it
        .filter(|r| !(r.len() == 1 && r.first().is_some_and(|f| f.is_empty())))
        .map(|r| r.get(idx).cloned().unwrap_or_default())
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_with_quotes_commas_and_newlines() {
        let rows: [[&str; 3]; 3] = [
            ["Question", "Query", "x"],
            [
                "Is there a car, maybe?",
                "TypeOf(x, Car)^Moving(x)",
                "say \"hi\"",
            ],
            ["two\nlines", "", " padded "],
        ];
        let mut out = String::new();
        for r in &rows {
            write_record(&mut out, r);
        }
        let back = parse_csv(&out).unwrap();
        assert_eq!(back.len(), 3);
        for (a, b) in back.iter().zip(rows.iter()) {
            assert_eq!(a, &b.iter().map(|s| s.to_string()).collect::<Vec<_>>());
        }
    }

    #[test]
    fn errors_and_columns() {
        assert_eq!(
            parse_csv("a,\"b\n"),
            Err(CsvError::UnterminatedQuote { line: 1 })
        );
        assert_eq!(parse_csv("a,b\"c\n"), Err(CsvError::StrayQuote { line: 1 }));
        assert_eq!(
            parse_csv("a,\"b\"c\n"),
            Err(CsvError::StrayQuote { line: 1 })
        );
        assert_eq!(
            column("Q,A\r\n\"x, y\",1\r\nz,2\r\n", "Q").unwrap(),
            vec!["x, y", "z"]
        );
        assert!(matches!(
            column("A,B\n1,2\n", "Q"),
            Err(CsvError::MissingColumn { .. })
        ));
        assert_eq!(column("", "Q"), Err(CsvError::Empty));
    }
}
