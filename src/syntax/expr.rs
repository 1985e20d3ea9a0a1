//! Plant expressions: `0.2/s*e^-7.4s`, `5.6*e^-93.9s/(40.2s+1)`,
//! `exp(-93.9*s)*5.6/(40.2*s+1)`, `e^-10s/(s+1)^2`, …
//!
//! Grammar (`*` may be left out between factors, spaces are ignored):
//!
//! ```text
//! expr   := [+|-] term (('+'|'-') term)*
//! term   := power (('*'|'/')? power)*
//! power  := atom ('^' [+|-] integer)?
//! atom   := number | 's' | '(' expr ')' | 'e' '^' delay | 'exp' '(' expr ')'
//! delay  := '(' expr ')' | [+|-] [number] ['*'] 's'
//! ```
//!
//! Numbers are decimal (`1e-3`, `.5`). Each delay factor `e^{−θs}` must have a
//! non-positive exponent; several add up. Sums are allowed between terms with
//! the same delay. The result must be proper. Every error names the problem and
//! the 1-based column it was found at.

use alloc::string::{String, ToString};
use alloc::vec;
use alloc::vec::Vec;
use core::fmt;

use crate::poly::{add, mul, trim, TransferFunction};
#[allow(unused_imports)] // f64 methods under no_std
use num_traits::Float;

/// A plant expression that could not be parsed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ParseError {
    /// What is wrong.
    pub message: String,
    /// 1-based column (character) where the problem was found.
    pub column: usize,
    /// The expression.
    pub input: String,
}

/// The longest expression accepted (characters).
pub const MAX_INPUT: usize = 4096;
/// The deepest nesting of parentheses (and `exp(…)`, `e^(…)`) accepted: the
/// parser recurses once per level.
pub const MAX_DEPTH: usize = 64;
/// Characters of the input shown on each side of the caret in an error.
const WINDOW: usize = 30;

impl fmt::Display for ParseError {
    /// The message, then the input with a caret under the column; a long
    /// input is shown as a window of it around the caret.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{} at column {}", self.message, self.column)?;
        let chars: Vec<char> = self.input.chars().collect();
        let at = self.column.saturating_sub(1).min(chars.len());
        let from = at.saturating_sub(WINDOW);
        let to = at.saturating_add(WINDOW).min(chars.len());
        let head = if from > 0 { "…" } else { "" };
        let tail = if to < chars.len() { "…" } else { "" };
        let shown: String = chars.get(from..to).unwrap_or(&[]).iter().collect();
        writeln!(f, "  {head}{shown}{tail}")?;
        let pad = at.saturating_sub(from).saturating_add(head.chars().count());
        write!(f, "  {}^", " ".repeat(pad))
    }
}

impl core::error::Error for ParseError {}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Tok {
    Num(f64),
    S,
    E,
    Exp,
    LParen,
    RParen,
    Plus,
    Minus,
    Star,
    Slash,
    Caret,
    End,
}

fn describe(t: Tok) -> String {
    match t {
        Tok::Num(v) => alloc::format!("number {v}"),
        Tok::S => "'s'".into(),
        Tok::E => "'e'".into(),
        Tok::Exp => "'exp'".into(),
        Tok::LParen => "'('".into(),
        Tok::RParen => "')'".into(),
        Tok::Plus => "'+'".into(),
        Tok::Minus => "'-'".into(),
        Tok::Star => "'*'".into(),
        Tok::Slash => "'/'".into(),
        Tok::Caret => "'^'".into(),
        Tok::End => "end of expression".into(),
    }
}

struct Lexed {
    toks: Vec<(Tok, usize)>,
}

fn lex(input: &str) -> Result<Lexed, (String, usize)> {
    let chars: Vec<char> = input.chars().collect();
    let mut toks = Vec::new();
    let mut i = 0usize;
    let at = |i: usize| chars.get(i).copied();
    while let Some(c) = at(i) {
        let col = i.saturating_add(1);
        if c.is_whitespace() {
            i = i.saturating_add(1);
            continue;
        }
        if c.is_ascii_digit() || c == '.' {
            let start = i;
            while at(i).is_some_and(|c| c.is_ascii_digit() || c == '.') {
                i = i.saturating_add(1);
            }
            // exponent: e or E followed by a digit, or a sign and a digit
            if let Some('e' | 'E') = at(i) {
                let n1 = at(i.saturating_add(1));
                let n2 = at(i.saturating_add(2));
                let digit = |c: Option<char>| c.is_some_and(|c| c.is_ascii_digit());
                if digit(n1) || (matches!(n1, Some('+' | '-')) && digit(n2)) {
                    i = i.saturating_add(2);
                    while digit(at(i)) {
                        i = i.saturating_add(1);
                    }
                }
            }
            let text: String = chars.get(start..i).unwrap_or(&[]).iter().collect();
            let v: f64 = text
                .parse()
                .map_err(|_| (alloc::format!("malformed number '{text}'"), col))?;
            toks.push((Tok::Num(v), col));
            continue;
        }
        let tok = match c {
            '(' | '[' => Tok::LParen,
            ')' | ']' => Tok::RParen,
            '+' => Tok::Plus,
            '-' | '−' => Tok::Minus,
            '*' | '·' | '×' => Tok::Star,
            '/' => Tok::Slash,
            '^' => Tok::Caret,
            's' => Tok::S,
            'e' if at(i.saturating_add(1)) == Some('x') && at(i.saturating_add(2)) == Some('p') => {
                i = i.saturating_add(2);
                Tok::Exp
            }
            'e' => Tok::E,
            _ => {
                let word: String = chars
                    .get(i..)
                    .unwrap_or(&[])
                    .iter()
                    .take_while(|c| c.is_alphanumeric() || **c == '_')
                    .collect();
                let shown = if word.is_empty() { c.to_string() } else { word };
                return Err((
                    alloc::format!(
                        "unknown symbol '{shown}' (expected a number, 's', 'e^…' or 'exp(…)')"
                    ),
                    col,
                ));
            }
        };
        toks.push((tok, col));
        i = i.saturating_add(1);
    }
    toks.push((Tok::End, chars.len().saturating_add(1)));
    Ok(Lexed { toks })
}

/// A rational function with one dead time, during parsing.
#[derive(Debug, Clone)]
struct Val {
    num: Vec<f64>,
    den: Vec<f64>,
    delay: f64,
}

impl Val {
    fn constant(c: f64) -> Self {
        Val {
            num: vec![c],
            den: vec![1.0],
            delay: 0.0,
        }
    }
    fn s() -> Self {
        Val {
            num: vec![1.0, 0.0],
            den: vec![1.0],
            delay: 0.0,
        }
    }
    fn mul(&self, o: &Val) -> Val {
        Val {
            num: mul(&self.num, &o.num),
            den: mul(&self.den, &o.den),
            delay: self.delay + o.delay,
        }
    }
    fn inv(&self) -> Option<Val> {
        if self.num.iter().all(|v| *v == 0.0) {
            return None;
        }
        Some(Val {
            num: self.den.clone(),
            den: self.num.clone(),
            delay: -self.delay,
        })
    }
    fn neg(&self) -> Val {
        Val {
            num: self.num.iter().map(|v| -v).collect(),
            den: self.den.clone(),
            delay: self.delay,
        }
    }
}

struct Parser<'a> {
    toks: &'a [(Tok, usize)],
    pos: usize,
    /// Current nesting of parentheses.
    depth: usize,
}

type PResult<T> = Result<T, (String, usize)>;

impl Parser<'_> {
    /// An expression inside the parenthesis at column `col`, one level deeper.
    fn nested(&mut self, col: usize) -> PResult<Val> {
        if self.depth >= MAX_DEPTH {
            return Err((
                alloc::format!("parentheses nested more than {MAX_DEPTH} deep"),
                col,
            ));
        }
        self.depth = self.depth.saturating_add(1);
        let v = self.expr();
        self.depth = self.depth.saturating_sub(1);
        v
    }

    fn peek(&self) -> (Tok, usize) {
        self.toks.get(self.pos).copied().unwrap_or((Tok::End, 0))
    }
    fn bump(&mut self) -> (Tok, usize) {
        let t = self.peek();
        self.pos = self.pos.saturating_add(1);
        t
    }
    fn expect_rparen(&mut self, open_col: usize) -> PResult<()> {
        match self.peek() {
            (Tok::RParen, _) => {
                self.bump();
                Ok(())
            }
            (Tok::End, _) => Err((
                "unbalanced parentheses: '(' is never closed".into(),
                open_col,
            )),
            (t, c) => Err((alloc::format!("expected ')' but found {}", describe(t)), c)),
        }
    }

    fn expr(&mut self) -> PResult<Val> {
        let mut neg = false;
        match self.peek().0 {
            Tok::Minus => {
                self.bump();
                neg = true;
            }
            Tok::Plus => {
                self.bump();
            }
            _ => {}
        }
        let mut acc = self.term()?;
        if neg {
            acc = acc.neg();
        }
        loop {
            let (t, col) = self.peek();
            let sign = match t {
                Tok::Plus => 1.0,
                Tok::Minus => -1.0,
                _ => return Ok(acc),
            };
            self.bump();
            let mut rhs = self.term()?;
            if sign < 0.0 {
                rhs = rhs.neg();
            }
            if (acc.delay - rhs.delay).abs() > 0.0 {
                return Err((
                    "cannot add terms with different delays (the result has no single dead time)"
                        .into(),
                    col,
                ));
            }
            acc = Val {
                num: add(&mul(&acc.num, &rhs.den), &mul(&rhs.num, &acc.den)),
                den: mul(&acc.den, &rhs.den),
                delay: acc.delay,
            };
            check_degree(&acc, col)?;
        }
    }

    fn term(&mut self) -> PResult<Val> {
        let mut acc = self.power()?;
        loop {
            let (t, col) = self.peek();
            match t {
                Tok::Star => {
                    self.bump();
                    acc = acc.mul(&self.power()?);
                    check_degree(&acc, col)?;
                }
                Tok::Slash => {
                    self.bump();
                    let (_, rcol) = self.peek();
                    let rhs = self.power()?;
                    let inv = rhs
                        .inv()
                        .ok_or_else(|| ("division by zero".to_string(), rcol))?;
                    acc = acc.mul(&inv);
                }
                Tok::Num(_) => {
                    // `2 3` or `(s+1)2`: a number is never multiplied implicitly
                    return Err((
                        "a number after another factor: write '*' between them".into(),
                        col,
                    ));
                }
                Tok::S | Tok::E | Tok::Exp | Tok::LParen => {
                    acc = acc.mul(&self.power()?);
                    check_degree(&acc, col)?;
                }
                _ => return Ok(acc),
            }
        }
    }

    /// An optional `+` or `-` (taken): whether it is a minus.
    fn sign_is_minus(&mut self) -> bool {
        match self.peek().0 {
            Tok::Minus => {
                self.bump();
                true
            }
            Tok::Plus => {
                self.bump();
                false
            }
            _ => false,
        }
    }

    fn power(&mut self) -> PResult<Val> {
        let base = self.atom()?;
        if self.peek().0 != Tok::Caret {
            return Ok(base);
        }
        let (_, caret_col) = self.bump();
        let sign = if self.sign_is_minus() { -1i32 } else { 1 };
        let (t, col) = self.bump();
        let Tok::Num(n) = t else {
            return Err((
                alloc::format!(
                    "expected an integer power after '^' but found {}",
                    describe(t)
                ),
                col,
            ));
        };
        if n != n.trunc() || n > f64::from(MAX_DEGREE) {
            return Err((
                alloc::format!("powers must be integers from -{MAX_DEGREE} to {MAX_DEGREE}"),
                col,
            ));
        }
        let _ = caret_col;
        #[allow(clippy::cast_possible_truncation)]
        let n = (n as i32).saturating_mul(sign);
        let deg = base.num.len().max(base.den.len()).saturating_sub(1);
        if deg.saturating_mul(n.unsigned_abs() as usize) > MAX_DEGREE as usize {
            return Err((
                alloc::format!("the power makes a polynomial of degree above {MAX_DEGREE}"),
                col,
            ));
        }
        let mut out = Val::constant(1.0);
        for _ in 0..n.unsigned_abs() {
            out = out.mul(&base);
        }
        if n < 0 {
            out = out
                .inv()
                .ok_or_else(|| ("division by zero".to_string(), col))?;
        }
        Ok(out)
    }

    fn atom(&mut self) -> PResult<Val> {
        let (t, col) = self.bump();
        match t {
            Tok::Num(v) => Ok(Val::constant(v)),
            Tok::S => Ok(Val::s()),
            Tok::LParen => {
                let v = self.nested(col)?;
                self.expect_rparen(col)?;
                Ok(v)
            }
            Tok::Exp => {
                let (t2, c2) = self.bump();
                if t2 != Tok::LParen {
                    return Err(("expected '(' after 'exp'".into(), c2));
                }
                let v = self.nested(c2)?;
                self.expect_rparen(c2)?;
                delay_of(&v, c2.saturating_add(1))
            }
            Tok::E => {
                let (t2, c2) = self.bump();
                if t2 != Tok::Caret {
                    return Err((
                        "expected '^' after 'e' (a delay is written e^-θs)".into(),
                        c2,
                    ));
                }
                let (t3, c3) = self.peek();
                if t3 == Tok::LParen {
                    self.bump();
                    let v = self.nested(c3)?;
                    self.expect_rparen(c3)?;
                    return delay_of(&v, c3.saturating_add(1));
                }
                // [+|-] [number] ['*'] 's'
                let sign = if self.sign_is_minus() { -1.0 } else { 1.0 };
                let mut coef = 1.0;
                if let Tok::Num(v) = self.peek().0 {
                    self.bump();
                    coef = v;
                }
                if self.peek().0 == Tok::Star {
                    self.bump();
                }
                let (t4, c4) = self.bump();
                if t4 != Tok::S {
                    return Err((
                        alloc::format!(
                            "expected 's' in the delay exponent but found {} (write e^-θs)",
                            describe(t4)
                        ),
                        c4,
                    ));
                }
                // `e^-5s^2` is e^(−5s²) to a reader (a power binds to
                // the `s` before it), not (e^−5s)²: no delay, refused here
                // where the power stands
                let (t5, c5) = self.peek();
                if t5 == Tok::Caret {
                    return Err((
                        "a power of s in a delay exponent is no delay: e^-θs takes no '^' after its s (for a squared delay write (e^-θs)^2)".into(),
                        c5,
                    ));
                }
                let v = Val {
                    num: vec![sign * coef, 0.0],
                    den: vec![1.0],
                    delay: 0.0,
                };
                delay_of(&v, c3)
            }
            Tok::End => Err(("unexpected end of expression".into(), col)),
            Tok::RParen => Err((
                "unbalanced parentheses: ')' without a matching '('".into(),
                col,
            )),
            other => Err((alloc::format!("unexpected {}", describe(other)), col)),
        }
    }
}

pub use crate::poly::MAX_DEGREE;

fn check_degree(v: &Val, col: usize) -> PResult<()> {
    if v.num.len().max(v.den.len()) > usize::from(MAX_DEGREE) + 1 {
        return Err((
            alloc::format!("the expression builds a polynomial of degree above {MAX_DEGREE}"),
            col,
        ));
    }
    Ok(())
}

/// `e^{v}` for `v = −θ·s`.
fn delay_of(v: &Val, col: usize) -> PResult<Val> {
    let num = trim(&v.num);
    let den = trim(&v.den);
    let linear = v.delay == 0.0
        && den.len() == 1
        && num.len() <= 2
        && num.last().is_some_and(|c| *c == 0.0 || num.len() == 1);
    let (c, d0) = match (num.as_slice(), den.first()) {
        ([a, b], Some(d)) if linear && *b == 0.0 => (a / d, 0.0),
        ([b], Some(_)) if linear => (0.0, *b),
        _ => return Err(("a delay exponent must be of the form -θ·s".into(), col)),
    };
    if d0 != 0.0 {
        return Err((
            "a delay exponent must be of the form -θ·s (no constant term)".into(),
            col,
        ));
    }
    if c > 0.0 {
        return Err((
            "a delay with a positive exponent (e^{+θs}) is not causal".into(),
            col,
        ));
    }
    if !c.is_finite() {
        return Err(("the delay is not a finite number".into(), col));
    }
    Ok(Val {
        num: vec![1.0],
        den: vec![1.0],
        delay: -c,
    })
}

/// Parses a plant expression into a transfer function with dead time.
pub fn parse_plant(input: &str) -> Result<TransferFunction, ParseError> {
    let err = |(message, column): (String, usize)| ParseError {
        message,
        column,
        input: input.to_string(),
    };
    if input.trim().is_empty() {
        return Err(err(("empty expression".into(), 1)));
    }
    if input.chars().nth(MAX_INPUT).is_some() {
        return Err(err((
            alloc::format!(
                "the expression is {} characters long; the limit is {MAX_INPUT}",
                input.chars().count()
            ),
            MAX_INPUT.saturating_add(1),
        )));
    }
    let lexed = lex(input).map_err(err)?;
    let mut p = Parser {
        toks: &lexed.toks,
        pos: 0,
        depth: 0,
    };
    let v = p.expr().map_err(err)?;
    let (t, col) = p.peek();
    match t {
        Tok::End => {}
        Tok::RParen => {
            return Err(err((
                "unbalanced parentheses: ')' without a matching '('".into(),
                col,
            )))
        }
        other => return Err(err((alloc::format!("unexpected {}", describe(other)), col))),
    }
    if v.delay < 0.0 {
        return Err(err((
            "a delay in the denominator gives a positive exponent (e^{+θs}), which is not causal"
                .into(),
            1,
        )));
    }
    let num = trim(&v.num);
    let den = trim(&v.den);
    if num.iter().any(|x| !x.is_finite()) || den.iter().any(|x| !x.is_finite()) {
        return Err(err(("a coefficient is not a finite number".into(), 1)));
    }
    if num.iter().all(|x| *x == 0.0) {
        return Err(err(("the transfer function is zero".into(), 1)));
    }
    // normalize: denominator's lowest non-zero coefficient magnitude 1
    let scale = den
        .iter()
        .rev()
        .find(|x| **x != 0.0)
        .map_or(1.0, |x| x.abs());
    let num: Vec<f64> = num.iter().map(|x| x / scale).collect();
    let den: Vec<f64> = den.iter().map(|x| x / scale).collect();
    if num.len() > den.len() {
        return Err(err((
            alloc::format!(
                "improper transfer function: numerator degree {} is above denominator degree {}",
                num.len().saturating_sub(1),
                den.len().saturating_sub(1)
            ),
            1,
        )));
    }
    TransferFunction::new(&num, &den, v.delay).map_err(|e| err((alloc::format!("{e}"), 1)))
}

impl core::str::FromStr for TransferFunction {
    type Err = ParseError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        parse_plant(s)
    }
}

/// serde for an optional transfer function written as a plant expression
/// (`plant = "0.2/s*e^-7.4s"` in a scenario file): serialized by its
/// [`Display`](core::fmt::Display) form, read by [`parse_plant`], whose error
/// (message, column, caret) becomes the deserializer's.
#[cfg(feature = "serde")]
pub mod as_expression {
    use super::{parse_plant, TransferFunction};
    use alloc::string::{String, ToString};

    /// Writes `Some(tf)` as its expression, `None` as nothing.
    pub fn serialize<S: serde::Serializer>(
        tf: &Option<TransferFunction>,
        s: S,
    ) -> Result<S::Ok, S::Error> {
        match tf {
            Some(tf) => s.serialize_some(&tf.to_string()),
            None => s.serialize_none(),
        }
    }

    /// Reads an expression into a transfer function.
    pub fn deserialize<'de, D: serde::Deserializer<'de>>(
        d: D,
    ) -> Result<Option<TransferFunction>, D::Error> {
        let text: Option<String> = serde::Deserialize::deserialize(d)?;
        text.map(|t| parse_plant(&t).map_err(serde::de::Error::custom))
            .transpose()
    }
}
