//! Expressions in x, y, t (and the constant `pi`) as scenes write them: parsed once,
//! evaluated fast, and differentiated exactly (exmex's symbolic derivatives).
//!
//! Piecewise expressions are written with `abs` (max(z, 0) = (z + abs(z)) / 2). exmex
//! cannot differentiate `abs`, so each `abs(z)` is differentiated on its branch: it is
//! rewritten as `s_k * (z)` with a sign variable s_k, exmex differentiates that (s_k is
//! constant on a branch), and evaluation sets s_k = sign(z(x, y, t)). Where the law needs a
//! derivative to be continuous, the branches agree at z = 0, so the choice there does not
//! matter.

mod program;

use crate::error::{Error, Result};
use exmex::Differentiate;
use exmex::prelude::*;
pub use program::Program;
use std::cell::RefCell;
use std::path::Path;
use std::sync::{Arc, OnceLock};

/// Inputs an expression may read: x, y, t, pi, then the sign variables s0, s1, ...
const NAMED: [&str; 4] = ["x", "y", "t", "pi"];

/// A parsed expression in x, y, t (and the constant `pi`), evaluated without re-parsing.
#[derive(Debug, Clone)]
pub struct Expr {
    /// The source text (for messages).
    pub text: String,
    // Boxed: a FlatEx keeps its nodes inline and is several kilobytes, which overflowed
    // the 2 MiB stack of test threads once a Scene was moved around.
    /// The expression with every `abs(z_k)` written as `s_k*(z_k)` (its branch form).
    flat: Box<FlatEx<f64>>,
    /// For each variable of `flat` (alphabetical order), which input it reads.
    slots: Vec<usize>,
    /// The arguments z_k of the `abs` calls, whose signs are the s_k.
    signs: Vec<Expr>,
    /// The expression compiled ([`Program`]) at its first evaluation (a derived field's
    /// intermediate steps are never evaluated); None inside if exmex wrote text the
    /// compiler does not read (then exmex evaluates it).
    program: OnceLock<Option<Arc<Program>>>,
}

thread_local! {
    /// Scratch registers of [`Expr::eval`].
    static REGISTERS: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
}

impl Expr {
    /// Parse `text`; `file` and `field` name the place for error messages.
    pub fn parse(text: &str, file: &Path, field: &str) -> Result<Self> {
        let bad = |msg: String| Error::input(file, field, msg);
        let (branch, arguments) =
            branch_form(text).map_err(|m| bad(format!("expression '{text}': {m}")))?;
        let signs = arguments
            .iter()
            .map(|a| Expr::parse(a, file, field))
            .collect::<Result<Vec<_>>>()?;
        let flat = FlatEx::<f64>::parse(&branch).map_err(|e| {
            bad(format!("cannot parse expression '{text}' ({e}); use x, y, t, numbers, + - * / ^ and functions such as sin, cos, exp, sqrt, abs"))
        })?;
        let slots = slots_of(&flat, signs.len()).map_err(|v| {
            bad(format!(
                "expression '{text}' uses unknown variable '{v}'; only x, y, t and pi are defined"
            ))
        })?;
        Ok(Expr {
            text: text.to_string(),
            flat: Box::new(flat),
            slots,
            signs,
            program: OnceLock::new(),
        })
    }

    /// A number as an expression.
    pub fn constant(v: f64) -> Self {
        Self::parse(&format!("{v}"), Path::new(""), "").expect("a number parses")
    }

    /// Its [`Program`], compiled at the first call.
    fn program(&self) -> Option<&Program> {
        self.program
            .get_or_init(|| compile(&[self]).map(Arc::new))
            .as_deref()
    }

    /// Evaluate at (x, y, t). Non-finite values are returned as they are; callers check.
    pub fn eval(&self, x: f64, y: f64, t: f64) -> f64 {
        if let Some(program) = self.program() {
            let mut out = [0.0];
            REGISTERS.with_borrow_mut(|r| program.eval_point(x, y, t, r, &mut out));
            return out[0];
        }
        self.eval_interpreted(x, y, t)
    }

    /// The error for this expression of `field` in `file` not finite at (x, y, t).
    pub fn not_finite(&self, file: &Path, field: &str, x: f64, y: f64, t: f64) -> Error {
        Error::input(
            file,
            field,
            format!(
                "expression '{}' is not finite at x = {x}, y = {y}, t = {t}; fix the expression",
                self.text
            ),
        )
    }

    /// Whether the expression reads t.
    pub fn reads_time(&self) -> bool {
        self.slots.contains(&2) || self.signs.iter().any(|z| z.reads_time())
    }

    /// Whether [`Expr::eval`] runs a compiled [`Program`].
    pub fn is_compiled(&self) -> bool {
        self.program().is_some()
    }

    /// Evaluate with exmex's evaluator (what [`Expr::eval`] falls back to, and what the
    /// compiled program is checked against).
    pub fn eval_interpreted(&self, x: f64, y: f64, t: f64) -> f64 {
        let mut inputs = [0.0f64; 16];
        inputs[..4].copy_from_slice(&[x, y, t, std::f64::consts::PI]);
        for (k, z) in self.signs.iter().enumerate() {
            // sign(0) = +1: at a kink the branches' derivatives agree where the law needs
            // them to.
            inputs[4 + k] = if z.eval_interpreted(x, y, t) < 0.0 {
                -1.0
            } else {
                1.0
            };
        }
        let mut vals = [0.0f64; 16];
        for (k, &s) in self.slots.iter().enumerate() {
            vals[k] = inputs[s];
        }
        self.flat
            .eval(&vals[..self.slots.len()])
            .unwrap_or(f64::NAN)
    }

    /// The arguments z_k of the expression's `abs` calls: where one changes sign, the
    /// expression changes branch (its kinks and jumps lie on their zero lines).
    pub fn kinks(&self) -> &[Expr] {
        &self.signs
    }

    /// The exact partial derivative with respect to x (`var` 0), y (1) or t (2).
    pub fn partial(&self, var: usize) -> Expr {
        let name = NAMED[var];
        let derivative = match self.flat.var_names().iter().position(|v| v == name) {
            // exmex differentiates every operator a scene may use but abs, which the branch
            // form has removed; a failure here is a bug.
            Some(i) => (*self.flat)
                .clone()
                .partial(i)
                .expect("exmex differentiates the branch form"),
            None => FlatEx::<f64>::parse("0").expect("0 parses"),
        };
        let slots =
            slots_of(&derivative, self.signs.len()).expect("a derivative reads no new variable");
        Expr {
            text: format!("d/d{name} ({})", self.text),
            flat: Box::new(derivative),
            slots,
            signs: self.signs.clone(),
            program: OnceLock::new(),
        }
    }

    /// The expression in the syntax scenes are written in (x, y, t, pi, numbers, + - * / ^,
    /// functions), its branches written out: derived fields (a derivative, a combination)
    /// have no source text of their own. Each `abs(z)` differentiated on its branch appears
    /// as `signum(z)` (+1 at z = 0, as [`Expr::eval`] takes it).
    pub fn plain_text(&self) -> String {
        let mut body = plain_numbers(&self.flat.unparse());
        for (k, z) in self.signs.iter().enumerate() {
            body = body.replace(&format!("{{s{k}}}"), &format!("signum({})", z.plain_text()));
        }
        for name in NAMED {
            body = body.replace(&format!("{{{name}}}"), name);
        }
        body
    }

    /// The sum of `terms`, each a coefficient times an expression. Sign variables whose
    /// arguments have the same text become one: a derived field evaluates each kink once
    /// per point (a manufactured body force of `contact-mms` went from 12 sign evaluations
    /// to 1).
    pub fn combine(terms: &[(f64, &Expr)]) -> Expr {
        let mut text = String::new();
        let mut signs: Vec<Expr> = Vec::new();
        for (c, e) in terms {
            let mut body = plain_numbers(&e.flat.unparse());
            // Two passes (through a placeholder name) so that no renamed variable is renamed
            // again.
            for k in 0..e.signs.len() {
                body = body.replace(&format!("{{s{k}}}"), &format!("{{renamed{k}}}"));
            }
            for (k, z) in e.signs.iter().enumerate() {
                let j = match signs.iter().position(|s| s.text == z.text) {
                    Some(j) => j,
                    None => {
                        signs.push(z.clone());
                        signs.len() - 1
                    }
                };
                body = body.replace(&format!("{{renamed{k}}}"), &format!("{{s{j}}}"));
            }
            if !text.is_empty() {
                text.push('+');
            }
            text.push_str(&format!("({c})*({body})"));
        }
        if text.is_empty() {
            text.push('0');
        }
        let flat = FlatEx::<f64>::parse(&text).expect("a combination of parsed expressions parses");
        let slots = slots_of(&flat, signs.len()).expect("no new variable");
        let source: Vec<String> = terms
            .iter()
            .map(|(c, e)| format!("{c}*({})", e.text))
            .collect();
        Expr {
            text: source.join(" + "),
            flat: Box::new(flat),
            slots,
            signs,
            program: OnceLock::new(),
        }
    }
}

/// The expressions compiled into one [`Program`] whose outputs are their values, in order:
/// the operations they share are computed once. None if one of them holds text the compiler
/// does not read.
pub fn compile(exprs: &[&Expr]) -> Option<Program> {
    let mut builder = program::Builder::default();
    let outputs = exprs
        .iter()
        .map(|e| compile_into(&mut builder, e))
        .collect::<std::result::Result<Vec<u32>, String>>()
        .ok()?;
    Some(builder.program(&outputs))
}

fn compile_into(b: &mut program::Builder, e: &Expr) -> std::result::Result<u32, String> {
    let mut signs = Vec::with_capacity(e.signs.len());
    for z in &e.signs {
        let node = compile_into(b, z)?;
        signs.push(b.branch(node));
    }
    let variable = |b: &mut program::Builder, name: &str| match name {
        "x" => Some(b.x()),
        "y" => Some(b.y()),
        "t" => Some(b.t()),
        "pi" => Some(b.constant(std::f64::consts::PI)),
        _ => {
            let k: usize = name.strip_prefix('s')?.parse().ok()?;
            signs.get(k).copied()
        }
    };
    // The deep form's text is exmex's own structure, fully parenthesized (a parsed
    // expression's `unparse` is its source text, in the user's precedence).
    let deep = (*e.flat)
        .clone()
        .to_deepex()
        .map_err(|err| err.to_string())?;
    b.compile(deep.unparse(), &variable)
}

/// `text` with every number in exponent notation (as exmex unparses very small or large
/// constants, e.g. `7.5e-19`) written out in full, and the non-finite constants `inf` and
/// `NaN` (a constant 1/0 or 0/0 folded at parse) as `(1/0)` and `(0/0)`: what exmex's
/// parser reads back as numbers, not as variables.
fn plain_numbers(text: &str) -> String {
    let chars: Vec<char> = text.chars().collect();
    let identifier = |c: char| c.is_alphanumeric() || c == '_';
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let word_start = i == 0 || !(identifier(chars[i - 1]) || chars[i - 1] == '.');
        let non_finite = [("inf", "(1/0)"), ("NaN", "(0/0)")]
            .into_iter()
            .find(|(word, _)| {
                let n = word.len();
                word_start
                    && chars[i..].iter().take(n).copied().eq(word.chars())
                    && chars.get(i + n).is_none_or(|&c| !identifier(c))
            });
        if let Some((word, number)) = non_finite {
            out.push_str(number);
            i += word.len();
            continue;
        }
        let starts_number = c.is_ascii_digit()
            && (i == 0
                || !(chars[i - 1].is_alphanumeric() || chars[i - 1] == '_' || chars[i - 1] == '.'));
        if !starts_number {
            out.push(c);
            i += 1;
            continue;
        }
        let mut j = i;
        while j < chars.len() && (chars[j].is_ascii_digit() || chars[j] == '.') {
            j += 1;
        }
        if j < chars.len() && (chars[j] == 'e' || chars[j] == 'E') {
            let mut k = j + 1;
            if k < chars.len() && (chars[k] == '-' || chars[k] == '+') {
                k += 1;
            }
            if k < chars.len() && chars[k].is_ascii_digit() {
                while k < chars.len() && chars[k].is_ascii_digit() {
                    k += 1;
                }
                let literal: String = chars[i..k].iter().collect();
                let v: f64 = literal.parse().expect("a number literal");
                out.push_str(&format!("{v}"));
                i = k;
                continue;
            }
        }
        out.extend(&chars[i..j]);
        i = j;
    }
    out
}

/// For each variable of `flat`, the input it reads; Err(name) for an unknown one.
fn slots_of(flat: &FlatEx<f64>, n_signs: usize) -> std::result::Result<Vec<usize>, String> {
    flat.var_names()
        .iter()
        .map(|v| {
            if let Some(i) = NAMED.iter().position(|n| n == v) {
                return Ok(i);
            }
            match v.strip_prefix('s').and_then(|k| k.parse::<usize>().ok()) {
                Some(k) if k < n_signs && 4 + k < 16 => Ok(4 + k),
                _ => Err(v.clone()),
            }
        })
        .collect()
}

/// Rewrite every `abs(z)` of `text` as `({s_k}*(z))`; returns the new text and the z_k.
/// Nested calls keep their inner `abs` inside z_k (evaluated natively).
fn branch_form(text: &str) -> std::result::Result<(String, Vec<String>), String> {
    let mut out = String::new();
    let mut arguments = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find("abs(") {
        // `abs(` must start a name: not part of a longer identifier such as `fabs(`.
        let starts_name = rest[..i]
            .chars()
            .last()
            .is_none_or(|c| !(c.is_alphanumeric() || c == '_'));
        if !starts_name {
            out.push_str(&rest[..i + 4]);
            rest = &rest[i + 4..];
            continue;
        }
        out.push_str(&rest[..i]);
        let after = &rest[i + 4..];
        let mut depth = 1;
        let close = after
            .char_indices()
            .find(|&(_, c)| {
                match c {
                    '(' => depth += 1,
                    ')' => depth -= 1,
                    _ => {}
                }
                depth == 0
            })
            .map(|(j, _)| j)
            .ok_or("an abs( is not closed")?;
        // The same argument twice is one sign variable (one kink).
        let argument = after[..close].to_string();
        let k = match arguments.iter().position(|a| *a == argument) {
            Some(k) => k,
            None => {
                if arguments.len() >= 12 {
                    return Err("more than 12 distinct abs arguments".into());
                }
                arguments.push(argument);
                arguments.len() - 1
            }
        };
        out.push_str(&format!("({{s{k}}}*({}))", &after[..close]));
        rest = &after[close + 1..];
    }
    out.push_str(rest);
    Ok((out, arguments))
}

/// The distinct kink arguments (by text) of `exprs` ([`Expr::kinks`]).
pub fn distinct_kinks<'a>(exprs: impl IntoIterator<Item = &'a Expr>) -> Vec<&'a Expr> {
    let mut out: Vec<&Expr> = Vec::new();
    for e in exprs {
        for z in e.kinks() {
            if !out.iter().any(|k| k.text == z.text) {
                out.push(z);
            }
        }
    }
    out
}

/// Each kink of `kinks` at time `t` as a function of the point, for
/// [`crate::quadrature::split_triangle`] and [`crate::quadrature::segment_rule`].
pub fn kink_functions<'a>(kinks: &[&'a Expr], t: f64) -> Vec<KinkFunction<'a>> {
    kinks
        .iter()
        .map(|&z| Box::new(move |x: [f64; 2]| z.eval(x[0], x[1], t)) as KinkFunction<'a>)
        .collect()
}

/// A kink as a function of the point (shared by the threads of a load integral).
pub type KinkFunction<'a> = Box<dyn Fn([f64; 2]) -> f64 + Send + Sync + 'a>;

/// A vector field given by two expressions.
#[derive(Debug, Clone)]
pub struct VectorExpr(pub [Expr; 2]);

impl VectorExpr {
    /// Parse both components; errors name `field[0]` or `field[1]`.
    pub fn parse(e: &[String; 2], file: &Path, field: &str) -> Result<Self> {
        Ok(VectorExpr([
            Expr::parse(&e[0], file, &format!("{field}[0]"))?,
            Expr::parse(&e[1], file, &format!("{field}[1]"))?,
        ]))
    }
}
