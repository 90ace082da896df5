//! Expressions compiled into a flat program: what [`super::Expr::eval`] runs.
//!
//! exmex parses a scene's text and differentiates it; its evaluator keeps per-node
//! bookkeeping (which operand is already consumed) at every call, and a derived field (a
//! body force -div sigma(u), built from second derivatives of the displacement) repeats the
//! same subexpressions many times over. Measured on `contact-mms` at level 5, evaluating
//! took about 80% of a solve. No maintained crate compiles exmex's expressions, so this
//! module does it by hand, from the text exmex writes back (`unparse`, fully parenthesized):
//! - one node per distinct operation (hash-consed), shared between the fields compiled
//!   together, so a field and its derivatives, or the two components of a body force,
//!   compute a common subexpression once;
//! - integer powers as products (square and multiply), and fractional powers with a
//!   denominator 2 or 4 from one square root or one fourth root of their base
//!   (r^(k/4) = (sqrt(sqrt(r)))^k): the regularity family's five powers of one base cost
//!   two square roots and a few products;
//! - operations applied in exmex's order (its priorities, left to right among equals), so
//!   the values agree with exmex's to round-off.
//!
//! A program evaluates at one point ([`Program::eval_point`]) or at many points per call
//! ([`Program::eval_lanes`]), one operation over all the points at a time.

use std::collections::HashMap;

/// A function of one argument, as exmex names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Unary {
    Neg,
    Abs,
    Signum,
    /// -1 where the argument is negative, +1 elsewhere (0 included): the sign variables
    /// of [`super::Expr`]'s branch form.
    Branch,
    Sqrt,
    Cbrt,
    Exp,
    Ln,
    Log2,
    Log10,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sinh,
    Cosh,
    Tanh,
    Asinh,
    Acosh,
    Atanh,
    Floor,
    Round,
    Ceil,
    Trunc,
    Fract,
}

impl Unary {
    fn named(name: &str) -> Option<Unary> {
        use Unary::*;
        Some(match name {
            "-" => Neg,
            "abs" => Abs,
            "signum" => Signum,
            "sqrt" => Sqrt,
            "cbrt" => Cbrt,
            "exp" => Exp,
            "ln" | "log" => Ln,
            "log2" => Log2,
            "log10" => Log10,
            "sin" => Sin,
            "cos" => Cos,
            "tan" => Tan,
            "asin" => Asin,
            "acos" => Acos,
            "atan" => Atan,
            "sinh" => Sinh,
            "cosh" => Cosh,
            "tanh" => Tanh,
            "asinh" => Asinh,
            "acosh" => Acosh,
            "atanh" => Atanh,
            "floor" => Floor,
            "round" => Round,
            "ceil" => Ceil,
            "trunc" => Trunc,
            "fract" => Fract,
            _ => return None,
        })
    }

    #[inline]
    fn apply(self, a: f64) -> f64 {
        use Unary::*;
        match self {
            Neg => -a,
            Abs => a.abs(),
            Signum => a.signum(),
            Branch => {
                if a < 0.0 {
                    -1.0
                } else {
                    1.0
                }
            }
            Sqrt => a.sqrt(),
            Cbrt => a.cbrt(),
            Exp => a.exp(),
            Ln => a.ln(),
            Log2 => a.log2(),
            Log10 => a.log10(),
            Sin => a.sin(),
            Cos => a.cos(),
            Tan => a.tan(),
            Asin => a.asin(),
            Acos => a.acos(),
            Atan => a.atan(),
            Sinh => a.sinh(),
            Cosh => a.cosh(),
            Tanh => a.tanh(),
            Asinh => a.asinh(),
            Acosh => a.acosh(),
            Atanh => a.atanh(),
            Floor => a.floor(),
            Round => a.round(),
            Ceil => a.ceil(),
            Trunc => a.trunc(),
            Fract => a.fract(),
        }
    }
}

/// An operator of two arguments, with exmex's priority.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Binary {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
    Atan2,
    Min,
    Max,
}

impl Binary {
    /// exmex's priorities (operators.rs of exmex 0.20): ^ 4, / 3, * 2, - 1, + and the
    /// named ones 0.
    fn priority(self) -> i32 {
        match self {
            Binary::Pow => 4,
            Binary::Div => 3,
            Binary::Mul => 2,
            Binary::Sub => 1,
            _ => 0,
        }
    }

    fn commutative(self) -> bool {
        matches!(self, Binary::Add | Binary::Mul)
    }

    #[inline]
    fn apply(self, a: f64, b: f64) -> f64 {
        match self {
            Binary::Add => a + b,
            Binary::Sub => a - b,
            Binary::Mul => a * b,
            Binary::Div => a / b,
            Binary::Pow => a.powf(b),
            Binary::Atan2 => a.atan2(b),
            Binary::Min => a.min(b),
            Binary::Max => a.max(b),
        }
    }
}

/// One operation; operands are indices of earlier operations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Op {
    X,
    Y,
    T,
    /// A constant, by its bits (so that operations hash).
    Const(u64),
    Unary(Unary, u32),
    Binary(Binary, u32, u32),
}

/// Builds the operations of several expressions into one shared list.
#[derive(Debug, Default)]
pub(crate) struct Builder {
    ops: Vec<Op>,
    index: HashMap<Op, u32>,
}

impl Builder {
    fn value(&self, node: u32) -> Option<f64> {
        match self.ops[node as usize] {
            Op::Const(bits) => Some(f64::from_bits(bits)),
            _ => None,
        }
    }

    fn push(&mut self, op: Op) -> u32 {
        if let Some(&i) = self.index.get(&op) {
            return i;
        }
        let i = self.ops.len() as u32;
        self.ops.push(op);
        self.index.insert(op, i);
        i
    }

    pub(crate) fn x(&mut self) -> u32 {
        self.push(Op::X)
    }
    pub(crate) fn y(&mut self) -> u32 {
        self.push(Op::Y)
    }
    pub(crate) fn t(&mut self) -> u32 {
        self.push(Op::T)
    }
    pub(crate) fn constant(&mut self, v: f64) -> u32 {
        self.push(Op::Const(v.to_bits()))
    }

    /// -1 where `z` is negative, +1 elsewhere.
    pub(crate) fn branch(&mut self, z: u32) -> u32 {
        self.unary(Unary::Branch, z)
    }

    fn unary(&mut self, f: Unary, a: u32) -> u32 {
        if let Some(v) = self.value(a) {
            return self.constant(f.apply(v));
        }
        if f == Unary::Neg
            && let Op::Unary(Unary::Neg, inner) = self.ops[a as usize]
        {
            return inner;
        }
        self.push(Op::Unary(f, a))
    }

    fn binary(&mut self, f: Binary, a: u32, b: u32) -> u32 {
        let (va, vb) = (self.value(a), self.value(b));
        if let (Some(x), Some(y)) = (va, vb) {
            return self.constant(f.apply(x, y));
        }
        // Identities exact in floating point (up to the sign of a zero): exmex's
        // derivatives are full of `- 0.0`, `* 1.0` and `0.0 - z`.
        match (f, va, vb) {
            (Binary::Add, Some(z), _) if z == 0.0 => return b,
            (Binary::Add | Binary::Sub, _, Some(z)) if z == 0.0 => return a,
            (Binary::Sub, Some(z), _) if z == 0.0 => return self.unary(Unary::Neg, b),
            (Binary::Mul, Some(o), _) if o == 1.0 => return b,
            (Binary::Mul | Binary::Div, _, Some(o)) if o == 1.0 => return a,
            (Binary::Mul, Some(m), _) if m == -1.0 => return self.unary(Unary::Neg, b),
            (Binary::Mul | Binary::Div, _, Some(m)) if m == -1.0 => {
                return self.unary(Unary::Neg, a);
            }
            (Binary::Pow, _, Some(p)) => return self.power(a, p),
            _ => {}
        }
        let (a, b) = if f.commutative() && b < a {
            (b, a)
        } else {
            (a, b)
        };
        self.push(Op::Binary(f, a, b))
    }

    /// a^p: products for an integer p, one square or fourth root of a for a p in quarters.
    fn power(&mut self, a: u32, p: f64) -> u32 {
        const LARGEST: f64 = 64.0;
        let quarters = 4.0 * p;
        if p.abs() > LARGEST || quarters.fract() != 0.0 {
            let pc = self.constant(p);
            return self.push(Op::Binary(Binary::Pow, a, pc));
        }
        let quarters = quarters as i64;
        let (base, k) = if quarters % 4 == 0 {
            (a, quarters / 4)
        } else if quarters % 2 == 0 {
            (self.unary(Unary::Sqrt, a), quarters / 2)
        } else {
            let root = self.unary(Unary::Sqrt, a);
            (self.unary(Unary::Sqrt, root), quarters)
        };
        if k == 0 {
            // exmex: a^0 = 1 for every a (powf).
            return self.constant(1.0);
        }
        let positive = self.integer_power(base, k.unsigned_abs());
        if k > 0 {
            positive
        } else {
            let one = self.constant(1.0);
            self.push(Op::Binary(Binary::Div, one, positive))
        }
    }

    fn integer_power(&mut self, a: u32, k: u64) -> u32 {
        if k == 1 {
            return a;
        }
        let half = self.integer_power(a, k / 2);
        let square = self.binary(Binary::Mul, half, half);
        if k % 2 == 0 {
            square
        } else {
            self.binary(Binary::Mul, square, a)
        }
    }

    /// Compile exmex's unparsed text (`{x}`, `{s0}` for variables, numbers as Rust prints
    /// them, every unary operator followed by a parenthesis); `variable` gives the node of a
    /// variable's name. Err(why) for text it does not read (the caller keeps exmex then).
    pub(crate) fn compile(
        &mut self,
        text: &str,
        variable: &dyn Fn(&mut Builder, &str) -> Option<u32>,
    ) -> Result<u32, String> {
        let mut parser = Parser {
            text: text.as_bytes(),
            at: 0,
        };
        let node = parser.sequence(self, variable)?;
        if parser.at != parser.text.len() {
            return Err(format!(
                "unexpected '{}' at {}",
                text[parser.at..].chars().next().unwrap_or(' '),
                parser.at
            ));
        }
        Ok(node)
    }

    /// The program computing `outputs` (nodes of this builder): only the operations they
    /// need, in order.
    pub(crate) fn program(&self, outputs: &[u32]) -> Program {
        let mut needed = vec![false; self.ops.len()];
        for &o in outputs {
            needed[o as usize] = true;
        }
        for i in (0..self.ops.len()).rev() {
            if !needed[i] {
                continue;
            }
            match self.ops[i] {
                Op::Unary(_, a) => needed[a as usize] = true,
                Op::Binary(_, a, b) => {
                    needed[a as usize] = true;
                    needed[b as usize] = true;
                }
                _ => {}
            }
        }
        let mut renumber = vec![u32::MAX; self.ops.len()];
        let mut code = Vec::new();
        for (i, op) in self.ops.iter().enumerate().filter(|(i, _)| needed[*i]) {
            renumber[i] = code.len() as u32;
            code.push(match *op {
                Op::Unary(f, a) => Op::Unary(f, renumber[a as usize]),
                Op::Binary(f, a, b) => Op::Binary(f, renumber[a as usize], renumber[b as usize]),
                other => other,
            });
        }
        Program {
            outputs: outputs.iter().map(|&o| renumber[o as usize]).collect(),
            code,
        }
    }
}

/// Reads exmex's unparsed text (see [`Builder::compile`]).
struct Parser<'a> {
    text: &'a [u8],
    at: usize,
}

impl Parser<'_> {
    fn peek(&self) -> Option<u8> {
        self.text.get(self.at).copied()
    }

    /// Nodes joined by binary operators, combined in exmex's order: higher priority first,
    /// left to right among equals; two literal numbers joined by + or * first of all.
    fn sequence(
        &mut self,
        b: &mut Builder,
        variable: &dyn Fn(&mut Builder, &str) -> Option<u32>,
    ) -> Result<u32, String> {
        let mut nodes = vec![self.node(b, variable)?];
        let mut ops = Vec::new();
        while let Some(op) = self.binary_operator() {
            ops.push(op);
            nodes.push(self.node(b, variable)?);
        }
        let literal: Vec<bool> = nodes.iter().map(|n| n.1).collect();
        let priority = |i: usize| {
            let bump = literal[i] && literal[i + 1] && ops[i].commutative();
            ops[i].priority() * 10 + if bump { 5 } else { 0 }
        };
        let mut order: Vec<usize> = (0..ops.len()).collect();
        order.sort_by_key(|&i| std::cmp::Reverse(priority(i)));
        // Spans of nodes already combined: span_of[i] = (first, last) node of the span
        // holding node i, valid at the spans' ends; value at the first node.
        let mut value: Vec<u32> = nodes.iter().map(|n| n.0).collect();
        let mut first: Vec<usize> = (0..nodes.len()).collect();
        let mut last: Vec<usize> = (0..nodes.len()).collect();
        for i in order {
            // Operator i joins the span ending at node i and the one starting at i + 1.
            let (l0, r1) = (first[i], last[i + 1]);
            let combined = b.binary(ops[i], value[l0], value[i + 1]);
            value[l0] = combined;
            last[l0] = r1;
            first[r1] = l0;
        }
        Ok(value[0])
    }

    fn binary_operator(&mut self) -> Option<Binary> {
        let op = match self.peek()? {
            b'+' => Binary::Add,
            b'-' => Binary::Sub,
            b'*' => Binary::Mul,
            b'/' => Binary::Div,
            b'^' => Binary::Pow,
            _ => {
                for (name, op) in [
                    ("atan2", Binary::Atan2),
                    ("min", Binary::Min),
                    ("max", Binary::Max),
                ] {
                    if self.text[self.at..].starts_with(name.as_bytes()) {
                        self.at += name.len();
                        return Some(op);
                    }
                }
                return None;
            }
        };
        self.at += 1;
        Some(op)
    }

    /// One node: (its operation, whether it is a literal number).
    fn node(
        &mut self,
        b: &mut Builder,
        variable: &dyn Fn(&mut Builder, &str) -> Option<u32>,
    ) -> Result<(u32, bool), String> {
        let c = self.peek().ok_or("the text ends where a value should be")?;
        let next = self.text.get(self.at + 1).copied();
        if c == b'(' {
            self.at += 1;
            let inner = self.sequence(b, variable)?;
            self.expect(b')')?;
            return Ok((inner, false));
        }
        if c == b'{' {
            let end = self.text[self.at..]
                .iter()
                .position(|&ch| ch == b'}')
                .ok_or("a variable's { is not closed")?;
            let name = std::str::from_utf8(&self.text[self.at + 1..self.at + end])
                .map_err(|e| e.to_string())?;
            self.at += end + 1;
            return variable(b, name)
                .map(|n| (n, false))
                .ok_or_else(|| format!("unknown variable '{name}'"));
        }
        let starts_number = |ch: u8| ch.is_ascii_digit() || ch == b'.' || ch == b'i' || ch == b'N';
        if starts_number(c) || (c == b'-' && next.is_some_and(starts_number)) {
            return self.number().map(|v| (b.constant(v), true));
        }
        // A unary operator: a name (or + / -) followed by its parenthesized argument.
        let len = self.text[self.at..]
            .iter()
            .position(|&ch| ch == b'(')
            .ok_or("a name without an argument")?;
        let name =
            std::str::from_utf8(&self.text[self.at..self.at + len]).map_err(|e| e.to_string())?;
        self.at += len + 1;
        let argument = self.sequence(b, variable)?;
        self.expect(b')')?;
        if name == "+" {
            return Ok((argument, false));
        }
        let f = Unary::named(name).ok_or_else(|| format!("unknown function '{name}'"))?;
        Ok((b.unary(f, argument), false))
    }

    fn number(&mut self) -> Result<f64, String> {
        let start = self.at;
        if self.peek() == Some(b'-') {
            self.at += 1;
        }
        for word in ["inf", "NaN"] {
            if self.text[self.at..].starts_with(word.as_bytes()) {
                self.at += word.len();
                let v = if word == "inf" {
                    f64::INFINITY
                } else {
                    f64::NAN
                };
                return Ok(if self.text[start] == b'-' { -v } else { v });
            }
        }
        while let Some(ch) = self.peek() {
            let exponent_sign = (ch == b'-' || ch == b'+')
                && matches!(self.text.get(self.at - 1), Some(b'e' | b'E'));
            if ch.is_ascii_digit() || ch == b'.' || ch == b'e' || ch == b'E' || exponent_sign {
                self.at += 1;
            } else {
                break;
            }
        }
        let literal = std::str::from_utf8(&self.text[start..self.at]).map_err(|e| e.to_string())?;
        literal
            .parse::<f64>()
            .map_err(|_| format!("bad number '{literal}'"))
    }

    fn expect(&mut self, c: u8) -> Result<(), String> {
        if self.peek() == Some(c) {
            self.at += 1;
            Ok(())
        } else {
            Err(format!("expected '{}' at {}", c as char, self.at))
        }
    }
}

/// A compiled list of operations and the outputs it computes.
#[derive(Debug, Clone, Hash)]
pub struct Program {
    code: Vec<Op>,
    outputs: Vec<u32>,
}

impl Program {
    /// Number of square roots it takes (a fourth root is two).
    pub fn square_roots(&self) -> usize {
        self.code
            .iter()
            .filter(|op| matches!(op, Op::Unary(Unary::Sqrt, _)))
            .count()
    }

    /// Number of operations other than x, y, t and constants.
    pub fn operations(&self) -> usize {
        self.code
            .iter()
            .filter(|op| matches!(op, Op::Unary(..) | Op::Binary(..)))
            .count()
    }

    /// Number of outputs.
    pub fn n_outputs(&self) -> usize {
        self.outputs.len()
    }

    /// Evaluate at one point; `registers` is scratch space (resized here), `out` receives
    /// one value per output.
    pub fn eval_point(&self, x: f64, y: f64, t: f64, registers: &mut Vec<f64>, out: &mut [f64]) {
        registers.resize(self.code.len(), 0.0);
        for i in 0..self.code.len() {
            let v = match self.code[i] {
                Op::X => x,
                Op::Y => y,
                Op::T => t,
                Op::Const(bits) => f64::from_bits(bits),
                Op::Unary(f, a) => f.apply(registers[a as usize]),
                Op::Binary(f, a, b) => f.apply(registers[a as usize], registers[b as usize]),
            };
            registers[i] = v;
        }
        for (o, &k) in out.iter_mut().zip(&self.outputs) {
            *o = registers[k as usize];
        }
    }

    /// Evaluate at the points (xs[l], ys[l]), one operation over all of them at a time;
    /// `out[o * n + l]` receives output o at point l (n = xs.len()).
    pub fn eval_lanes(
        &self,
        xs: &[f64],
        ys: &[f64],
        t: f64,
        registers: &mut Vec<f64>,
        out: &mut [f64],
    ) {
        let n = xs.len();
        registers.resize(self.code.len() * n, 0.0);
        for i in 0..self.code.len() {
            let (done, rest) = registers.split_at_mut(i * n);
            let r = &mut rest[..n];
            match self.code[i] {
                Op::X => r.copy_from_slice(xs),
                Op::Y => r.copy_from_slice(ys),
                Op::T => r.fill(t),
                Op::Const(bits) => r.fill(f64::from_bits(bits)),
                Op::Unary(f, a) => {
                    let a = &done[a as usize * n..][..n];
                    match f {
                        Unary::Neg => r.iter_mut().zip(a).for_each(|(r, a)| *r = -a),
                        Unary::Sqrt => r.iter_mut().zip(a).for_each(|(r, a)| *r = a.sqrt()),
                        _ => r.iter_mut().zip(a).for_each(|(r, &a)| *r = f.apply(a)),
                    }
                }
                Op::Binary(f, a, b) => {
                    let a = &done[a as usize * n..][..n];
                    let b = &done[b as usize * n..][..n];
                    let lanes = r.iter_mut().zip(a.iter().zip(b));
                    match f {
                        Binary::Add => lanes.for_each(|(r, (a, b))| *r = a + b),
                        Binary::Sub => lanes.for_each(|(r, (a, b))| *r = a - b),
                        Binary::Mul => lanes.for_each(|(r, (a, b))| *r = a * b),
                        Binary::Div => lanes.for_each(|(r, (a, b))| *r = a / b),
                        _ => lanes.for_each(|(r, (&a, &b))| *r = f.apply(a, b)),
                    }
                }
            }
        }
        for (o, &k) in self.outputs.iter().enumerate() {
            out[o * n..][..n].copy_from_slice(&registers[k as usize * n..][..n]);
        }
    }

    /// The k with every output equal to t^k times a function of (x, y) alone, for t > 0,
    /// read from the operations (not sampled): Some(Some(k)) when all outputs share it,
    /// Some(None) when every output is zero (any k), None when there is no such k.
    pub fn time_degree(&self) -> Option<Option<f64>> {
        // None: not homogeneous in t; Some(None): zero (any degree); Some(Some(k)): t^k g.
        let mut degree: Vec<Option<Option<f64>>> = Vec::with_capacity(self.code.len());
        let same = |a: Option<Option<f64>>, b: Option<Option<f64>>| match (a?, b?) {
            (None, k) | (k, None) => Some(k),
            (Some(p), Some(q)) if p == q => Some(Some(p)),
            _ => None,
        };
        for op in &self.code {
            let d = match *op {
                Op::X | Op::Y => Some(Some(0.0)),
                Op::T => Some(Some(1.0)),
                Op::Const(bits) => {
                    let v = f64::from_bits(bits);
                    if v == 0.0 {
                        Some(None)
                    } else {
                        Some(Some(0.0))
                    }
                }
                Op::Unary(f, a) => match (f, degree[a as usize]) {
                    (_, None) => None,
                    (Unary::Neg | Unary::Abs, d) => d,
                    (Unary::Signum | Unary::Branch, Some(_)) => Some(Some(0.0)),
                    (Unary::Sqrt, Some(d)) => Some(d.map(|k| k / 2.0)),
                    (Unary::Cbrt, Some(d)) => Some(d.map(|k| k / 3.0)),
                    (_, Some(Some(k))) if k == 0.0 => Some(Some(0.0)),
                    _ => None,
                },
                Op::Binary(f, a, b) => {
                    let (da, db) = (degree[a as usize], degree[b as usize]);
                    match f {
                        Binary::Add | Binary::Sub | Binary::Min | Binary::Max => same(da, db),
                        Binary::Mul => match (da, db) {
                            (Some(None), _) | (_, Some(None)) => Some(None),
                            (Some(Some(p)), Some(Some(q))) => Some(Some(p + q)),
                            _ => None,
                        },
                        Binary::Div => match (da, db) {
                            (Some(None), Some(Some(_))) => Some(None),
                            (Some(Some(p)), Some(Some(q))) => Some(Some(p - q)),
                            _ => None,
                        },
                        Binary::Pow => match (da, db, &self.code[b as usize]) {
                            (Some(Some(p)), Some(Some(q)), Op::Const(bits)) if q == 0.0 => {
                                Some(Some(p * f64::from_bits(*bits)))
                            }
                            (Some(Some(p)), Some(Some(q)), _) if p == 0.0 && q == 0.0 => {
                                Some(Some(0.0))
                            }
                            _ => None,
                        },
                        Binary::Atan2 => match same(da, db) {
                            Some(Some(_)) => Some(Some(0.0)),
                            _ => None,
                        },
                    }
                }
            };
            degree.push(d);
        }
        let mut common: Option<Option<f64>> = Some(None);
        for &o in &self.outputs {
            common = same(common, degree[o as usize]);
        }
        common
    }
}
