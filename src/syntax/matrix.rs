//! Multivariable plants written as MATLAB writes a matrix:
//! `[12.8e^-1s/(16.7s+1), -18.9e^-3s/(21s+1); 6.6e^-7s/(10.9s+1), -19.4e^-3s/(14.4s+1)]`
//! (rows separated by `;`, entries by `,`), every entry in the plant grammar
//! ([`super::parse_plant`]) or `0` for a channel without coupling.

use alloc::string::{String, ToString};
use alloc::vec::Vec;

use super::expr::{parse_plant, ParseError, MAX_INPUT};
use crate::poly::{TransferFunction, TransferMatrix};

/// Parses `[g11, g12; g21, g22]` into a [`TransferMatrix`]; an error names
/// the column in the whole input (an entry's own error shifted to where the
/// entry stands).
pub fn parse_matrix(input: &str) -> Result<TransferMatrix, ParseError> {
    let (rows, at) = parse_rows(input)?;
    let err = |message: String, column: usize| ParseError {
        message,
        column,
        input: input.to_string(),
    };
    let n = rows.len();
    if let Some(bad) = rows.iter().position(|r| r.len() != n) {
        return Err(err(
            alloc::format!(
                "a plant matrix is square: {n} row(s), and row {} has {} entries",
                bad + 1,
                rows.get(bad).map_or(0, Vec::len)
            ),
            at,
        ));
    }
    TransferMatrix::new(rows).map_err(|e| err(e.to_string(), at))
}

/// A column of transfer functions, `[d1; d2; …]` (a disturbance's channel
/// to each output: Wood–Berry's feed `[3.8e^-8.1s/(14.9s+1);
/// 4.9e^-3.4s/(13.2s+1)]`).
pub fn parse_column(input: &str) -> Result<Vec<TransferFunction>, ParseError> {
    let (rows, at) = parse_rows(input)?;
    if let Some(bad) = rows.iter().position(|r| r.len() != 1) {
        return Err(ParseError {
            message: alloc::format!(
                "a column has one entry a row ('[d1; d2]'), and row {} has {}",
                bad + 1,
                rows.get(bad).map_or(0, Vec::len)
            ),
            column: at,
            input: input.to_string(),
        });
    }
    Ok(rows.into_iter().flatten().collect())
}

/// The rows of `[a, b; c, d]` and the column of its first entry.
fn parse_rows(input: &str) -> Result<(Vec<Vec<TransferFunction>>, usize), ParseError> {
    let err = |message: String, column: usize| ParseError {
        message,
        column,
        input: input.to_string(),
    };
    if input.chars().nth(MAX_INPUT).is_some() {
        return Err(err(
            alloc::format!("the matrix is longer than {MAX_INPUT} characters"),
            MAX_INPUT,
        ));
    }
    let chars: Vec<char> = input.chars().collect();
    let first = chars.iter().position(|c| !c.is_whitespace()).unwrap_or(0);
    let last = chars.iter().rposition(|c| !c.is_whitespace()).unwrap_or(0);
    if chars.get(first) != Some(&'[') {
        return Err(err("a matrix starts with '['".into(), first + 1));
    }
    if chars.get(last) != Some(&']') || last == first {
        return Err(err("a matrix ends with ']'".into(), last + 1));
    }
    // entries at parenthesis depth 0, split at ',' and rows at ';'
    let mut rows: Vec<Vec<TransferFunction>> = Vec::new();
    let mut row: Vec<TransferFunction> = Vec::new();
    let (mut depth, mut start) = (0usize, first + 1);
    for i in first + 1..=last {
        let c = chars.get(i).copied().unwrap_or(']');
        match c {
            '(' => depth += 1,
            ')' => depth = depth.saturating_sub(1),
            ',' | ';' | ']' if depth == 0 => {
                let text: String = chars.get(start..i).unwrap_or(&[]).iter().collect();
                row.push(entry(&text, start, &err)?);
                if c != ',' {
                    rows.push(core::mem::take(&mut row));
                }
                start = i + 1;
            }
            _ => {}
        }
    }
    Ok((rows, first + 1))
}

/// One entry (starting at character `at` of the input): `0`, or a plant.
fn entry(
    text: &str,
    at: usize,
    err: &impl Fn(String, usize) -> ParseError,
) -> Result<TransferFunction, ParseError> {
    let lead = text.chars().take_while(|c| c.is_whitespace()).count();
    let t = text.trim();
    if t.is_empty() {
        return Err(err("an empty entry".into(), at + 1));
    }
    if t.parse::<f64>().is_ok_and(|v| v == 0.0) {
        return TransferFunction::new(&[0.0], &[1.0], 0.0).map_err(|e| err(e.to_string(), at + 1));
    }
    parse_plant(t).map_err(|e| err(e.message, at + lead + e.column))
}

impl core::str::FromStr for TransferMatrix {
    type Err = ParseError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        parse_matrix(s)
    }
}
