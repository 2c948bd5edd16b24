//! The parser of a Psi expression: a small recursive descent over
//!
//! ```text
//! sum     := product (('+' | '-') product)*
//! product := unary (('*' | '/') unary)*
//! unary   := ('-' | '+') unary | power
//! power   := primary (('^' | '**') unary)?          (right associative: 2^3^2 = 2^9, -x^2 = -(x^2))
//! primary := number | name | name '(' sum (',' sum)* ')' | '(' sum ')'
//! ```
//!
//! Names are the variables `x1`, `x2`, `x3`, the constants `pi` and `e`, and the functions of
//! [`Func`]. Errors give the 1-based character column in the expression.

/// A parsed expression.
#[derive(Debug, Clone, PartialEq)]
pub enum Node {
    Const(f64),
    /// x1, x2, x3 as 0, 1, 2.
    Var(usize),
    Neg(Box<Node>),
    Bin(BinOp, Box<Node>, Box<Node>),
    Call(Func, Vec<Node>),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
}

/// The functions an expression may call.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Func {
    Sqrt,
    Sin,
    Cos,
    Tan,
    Exp,
    Ln,
    Abs,
    Min,
    Max,
    Pow,
    Atan2,
    Hypot,
}

/// Every function name with its function and number of arguments (`log` is the natural logarithm).
pub const FUNCTIONS: &[(&str, Func, usize)] = &[
    ("sqrt", Func::Sqrt, 1),
    ("sin", Func::Sin, 1),
    ("cos", Func::Cos, 1),
    ("tan", Func::Tan, 1),
    ("exp", Func::Exp, 1),
    ("ln", Func::Ln, 1),
    ("log", Func::Ln, 1),
    ("abs", Func::Abs, 1),
    ("min", Func::Min, 2),
    ("max", Func::Max, 2),
    ("pow", Func::Pow, 2),
    ("atan2", Func::Atan2, 2),
    ("hypot", Func::Hypot, 2),
];

/// A syntax error: what is wrong, at which 1-based character column of the expression.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ParseError {
    pub column: usize,
    pub message: String,
}

impl std::fmt::Display for ParseError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "column {}: {}", self.column, self.message)
    }
}

/// The longest expression accepted (characters), and the deepest nesting: a parser that recurses
/// must not overflow the stack on hostile input (a chain a+a+... is a tree as deep as it is long, so
/// the length bounds the depth of evaluation too).
pub const MAX_CHARS: usize = 2_000;
pub const MAX_DEPTH: usize = 200;

/// Parses `text` into a [`Node`].
pub fn parse(text: &str) -> Result<Node, ParseError> {
    let chars: Vec<char> = text.chars().collect();
    if chars.len() > MAX_CHARS {
        return Err(ParseError { column: MAX_CHARS + 1, message: format!("the expression has {} characters; at most {MAX_CHARS} are allowed", chars.len()) });
    }
    let mut p = Parser { chars, pos: 0, depth: 0 };
    p.skip_space();
    if p.pos == p.chars.len() {
        return Err(p.error_here("the expression is empty"));
    }
    let node = p.sum()?;
    p.skip_space();
    if p.pos < p.chars.len() {
        return Err(p.error_here(&format!("unexpected {}", p.describe_here())));
    }
    Ok(node)
}

struct Parser {
    chars: Vec<char>,
    pos: usize,
    depth: usize,
}

impl Parser {
    fn skip_space(&mut self) {
        while self.pos < self.chars.len() && self.chars[self.pos].is_whitespace() {
            self.pos += 1;
        }
    }

    fn peek(&mut self) -> Option<char> {
        self.skip_space();
        self.chars.get(self.pos).copied()
    }

    fn error_at(&self, pos: usize, message: &str) -> ParseError {
        ParseError { column: pos + 1, message: message.to_string() }
    }

    fn error_here(&self, message: &str) -> ParseError {
        self.error_at(self.pos, message)
    }

    /// "'c'" for the character at the cursor, "the end" past it.
    fn describe_here(&self) -> String {
        match self.chars.get(self.pos) {
            Some(c) if c.is_control() => "a control character".into(),
            Some(c) => format!("'{c}'"),
            None => "end of the expression".into(),
        }
    }

    fn enter(&mut self) -> Result<(), ParseError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(self.error_here(&format!("the expression nests deeper than {MAX_DEPTH} levels")));
        }
        Ok(())
    }

    fn sum(&mut self) -> Result<Node, ParseError> {
        self.enter()?;
        let mut left = self.product()?;
        loop {
            let op = match self.peek() {
                Some('+') => BinOp::Add,
                Some('-') => BinOp::Sub,
                _ => break,
            };
            self.pos += 1;
            let right = self.product()?;
            left = Node::Bin(op, Box::new(left), Box::new(right));
        }
        self.depth -= 1;
        Ok(left)
    }

    fn product(&mut self) -> Result<Node, ParseError> {
        let mut left = self.unary()?;
        loop {
            let op = match self.peek() {
                // '**' is a power, handled in `power`
                Some('*') if self.chars.get(self.pos + 1) == Some(&'*') => break,
                Some('*') => BinOp::Mul,
                Some('/') => BinOp::Div,
                _ => break,
            };
            self.pos += 1;
            let right = self.unary()?;
            left = Node::Bin(op, Box::new(left), Box::new(right));
        }
        Ok(left)
    }

    fn unary(&mut self) -> Result<Node, ParseError> {
        self.enter()?;
        let node = match self.peek() {
            Some('-') => {
                self.pos += 1;
                Node::Neg(Box::new(self.unary()?))
            }
            Some('+') => {
                self.pos += 1;
                self.unary()?
            }
            _ => self.power()?,
        };
        self.depth -= 1;
        Ok(node)
    }

    fn power(&mut self) -> Result<Node, ParseError> {
        let base = self.primary()?;
        match self.peek() {
            Some('^') => self.pos += 1,
            Some('*') if self.chars.get(self.pos + 1) == Some(&'*') => self.pos += 2,
            _ => return Ok(base),
        }
        let exponent = self.unary()?;
        Ok(Node::Bin(BinOp::Pow, Box::new(base), Box::new(exponent)))
    }

    fn primary(&mut self) -> Result<Node, ParseError> {
        match self.peek() {
            None => Err(self.error_here("the expression ends where a number, a variable or '(' was expected")),
            Some('(') => {
                let open = self.pos;
                self.pos += 1;
                let inner = self.sum()?;
                if self.peek() != Some(')') {
                    return Err(self.error_here(&format!("expected ')' to close the '(' at column {}, found {}", open + 1, self.describe_here())));
                }
                self.pos += 1;
                Ok(inner)
            }
            Some(c) if c.is_ascii_digit() || c == '.' => self.number(),
            Some(c) if c.is_alphabetic() || c == '_' => self.name(),
            Some(_) => Err(self.error_here(&format!("unexpected {}: expected a number, a variable, a function or '('", self.describe_here()))),
        }
    }

    fn number(&mut self) -> Result<Node, ParseError> {
        let start = self.pos;
        let digits = |p: &mut Parser| {
            let s = p.pos;
            while p.pos < p.chars.len() && p.chars[p.pos].is_ascii_digit() {
                p.pos += 1;
            }
            p.pos - s
        };
        let mut n = digits(self);
        if self.chars.get(self.pos) == Some(&'.') {
            self.pos += 1;
            n += digits(self);
        }
        if n == 0 {
            return Err(self.error_at(start, "a number needs digits"));
        }
        if matches!(self.chars.get(self.pos), Some('e' | 'E')) {
            let mark = self.pos;
            self.pos += 1;
            if matches!(self.chars.get(self.pos), Some('+' | '-')) {
                self.pos += 1;
            }
            if digits(self) == 0 {
                return Err(self.error_at(mark, "the exponent of a number needs digits (as in 1.5e-3)"));
            }
        }
        let text: String = self.chars[start..self.pos].iter().collect();
        match text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(Node::Const(v)),
            _ => Err(self.error_at(start, &format!("{text} is not a finite number"))),
        }
    }

    fn name(&mut self) -> Result<Node, ParseError> {
        let start = self.pos;
        while self.pos < self.chars.len() && (self.chars[self.pos].is_alphanumeric() || self.chars[self.pos] == '_') {
            self.pos += 1;
        }
        let name: String = self.chars[start..self.pos].iter().collect();
        let shown = stamp::quote(&name);
        if self.peek() == Some('(') {
            let Some(&(_, func, arity)) = FUNCTIONS.iter().find(|f| f.0 == name) else {
                let known: Vec<&str> = FUNCTIONS.iter().map(|f| f.0).collect();
                return Err(self.error_at(start, &format!("unknown function '{shown}' (known: {})", known.join(", "))));
            };
            let open = self.pos;
            self.pos += 1;
            let mut args = vec![self.sum()?];
            while self.peek() == Some(',') {
                self.pos += 1;
                args.push(self.sum()?);
            }
            if self.peek() != Some(')') {
                return Err(self.error_here(&format!("expected ',' or ')' in the call of {name} opened at column {}, found {}", open + 1, self.describe_here())));
            }
            self.pos += 1;
            if args.len() != arity {
                return Err(self.error_at(start, &format!("{name} takes {arity} argument{}, got {}", if arity == 1 { "" } else { "s" }, args.len())));
            }
            return Ok(Node::Call(func, args));
        }
        match name.as_str() {
            "x1" => Ok(Node::Var(0)),
            "x2" => Ok(Node::Var(1)),
            "x3" => Ok(Node::Var(2)),
            "pi" => Ok(Node::Const(std::f64::consts::PI)),
            "e" => Ok(Node::Const(std::f64::consts::E)),
            _ if FUNCTIONS.iter().any(|f| f.0 == name) => Err(self.error_at(start, &format!("the function {name} needs its arguments in parentheses"))),
            _ => Err(self.error_at(start, &format!("unknown variable '{shown}': the variables are x1, x2, x3 and the constants pi, e"))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn col(text: &str) -> (usize, String) {
        let e = parse(text).unwrap_err();
        (e.column, e.message)
    }

    #[test]
    fn precedence_and_associativity() {
        use BinOp::*;
        let c = |v| Box::new(Node::Const(v));
        assert_eq!(parse("1 + 2 * 3").unwrap(), Node::Bin(Add, c(1.0), Box::new(Node::Bin(Mul, c(2.0), c(3.0)))));
        assert_eq!(parse("2^3^2").unwrap(), Node::Bin(Pow, c(2.0), Box::new(Node::Bin(Pow, c(3.0), c(2.0)))));
        assert_eq!(parse("-x1^2").unwrap(), Node::Neg(Box::new(Node::Bin(Pow, Box::new(Node::Var(0)), c(2.0)))));
        assert_eq!(parse("1 - 2 - 3").unwrap(), Node::Bin(Sub, Box::new(Node::Bin(Sub, c(1.0), c(2.0))), c(3.0)));
        assert_eq!(parse("x3 ** 2").unwrap(), parse("x3^2").unwrap());
        assert_eq!(parse("1.5e-3").unwrap(), Node::Const(1.5e-3));
        assert_eq!(parse(".5E+2").unwrap(), Node::Const(50.0));
    }

    #[test]
    fn errors_name_the_column() {
        assert_eq!(col("x1 + y").0, 6);
        assert!(col("x1 + y").1.contains("unknown variable 'y'"), "{:?}", col("x1 + y"));
        assert_eq!(col("x1 + foo(x2)").0, 6);
        assert!(col("x1 + foo(x2)").1.contains("unknown function 'foo'"));
        assert_eq!(col("x1 + * x2").0, 6);
        assert_eq!(col("(x1 + x2").0, 9);
        assert!(col("(x1 + x2").1.contains("')'"));
        assert_eq!(col("x1 x2").0, 4);
        assert_eq!(col("1e+").0, 2);
        assert_eq!(col("").0, 1);
        assert_eq!(col("sqrt(1, 2)").0, 1);
        assert!(col("sqrt(1, 2)").1.contains("takes 1 argument"));
        assert_eq!(col("sqrt + 1").0, 1);
        // columns count characters, not bytes
        assert_eq!(col("µ + x1").0, 1);
        assert_eq!(col("1 + µ").0, 5);
    }

    #[test]
    fn deep_nesting_is_an_error_not_a_stack_overflow() {
        assert!(col(&"1+".repeat(1500)).1.contains("at most 2000"));
        // a long flat chain is fine (its tree is as deep as it is long: the length limit bounds it)
        assert!(parse(&("1".to_string() + &"+1".repeat(999))).is_ok());
        let deep = "(".repeat(900) + "1" + &")".repeat(900);
        assert!(col(&deep).1.contains("nests deeper"));
        let minus = "-".repeat(1500) + "1";
        assert!(col(&minus).1.contains("nests deeper"));
    }

    use crate::test_rng::Rng;

    #[test]
    fn hundreds_of_random_and_mutated_expressions_give_a_tree_or_an_error_never_a_panic() {
        let mut rng = Rng(0x5eed_0031);
        let seeds = ["(x1 / 120)^2 + (x2 / 80)^2 + ((x3 - 40.5) / 40)^2 - 1", "sqrt(x1^2 + x2^2) - hypot(x3, 2) * atan2(x1, -x2)", "min(max(x1, x2), exp(-ln(abs(x3) + 1e-3))) ** 2 - pi * e"];
        let pieces = ["(", ")", "+", "-", "*", "/", "^", "**", ",", "x1", "x2", "x3", "x4", "1e308", "1e-320", "0", ".", "e", "pi", "sqrt", "atan2", "min(", " ", "µ", "\u{0}", "1e", "nan", "inf"];
        let (mut ok, mut err) = (0, 0);
        for k in 0..800 {
            let text: String = if k % 4 == 3 {
                (0..rng.below(40)).map(|_| pieces[rng.below(pieces.len())]).collect()
            } else {
                let mut c: Vec<char> = seeds[k % 3].chars().collect();
                for _ in 0..1 + rng.below(4) {
                    let at = rng.below(c.len() + 1);
                    match rng.below(3) {
                        0 if at < c.len() => {
                            c.remove(at);
                        }
                        1 => c.splice(at..at, pieces[rng.below(pieces.len())].chars()).for_each(drop),
                        _ => c.truncate(at),
                    }
                }
                c.into_iter().collect()
            };
            match parse(&text) {
                Ok(_) => {
                    ok += 1;
                    // and it evaluates (finite or not) without a panic
                    let e = crate::Expression::new(&text, 1.0).unwrap();
                    for x in [[0.0, 0.0, 0.0], [1.0, -2.0, 3.5], [1e300, -1e-300, 0.5]] {
                        let _ = e.jet(&nalgebra::Vector3::from(x));
                    }
                }
                Err(e) => {
                    err += 1;
                    assert!(e.column >= 1 && e.column <= text.chars().count() + 1, "column {} of {text:?}", e.column);
                    assert!(!e.message.is_empty() && e.message.len() < 400, "{}", e.message);
                }
            }
        }
        assert!(ok >= 20 && err >= 100, "{ok} parsed, {err} refused");
    }
}
