//! The arithmetic of cost declarations: numbers, names, `+ - * /`, comparisons (1 or 0),
//! parentheses and the calls `min`, `max`, `ceil`, `floor` and WGSL's `select(f, t, cond)`.
//! Names are resolved by the caller (a kernel's constants, its parameters, a light's fields,
//! another function's fetches), so the same expressions serve every declaration.

/// A parsed expression.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    /// A number.
    Num(f64),
    /// A name, e.g. `WG_SIZE`, `params.radius`, `l.blocker_samples`, `sample_map`.
    Name(String),
    /// `a op b`.
    Binary(char, Box<Expr>, Box<Expr>),
    /// A comparison (`<`, `<=`, `>`, `>=`, `==`, `!=`): 1 when it holds, else 0.
    Compare(String, Box<Expr>, Box<Expr>),
    /// `-a`.
    Negate(Box<Expr>),
    /// `f(args…)`.
    Call(String, Vec<Expr>),
}

impl Expr {
    /// Parses `text`; the error says what was expected where.
    pub fn parse(text: &str) -> Result<Expr, String> {
        let tokens = tokenize(text)?;
        let mut p = Parser { tokens, at: 0 };
        let e = p.comparison()?;
        match p.tokens.get(p.at) {
            None => Ok(e),
            Some(t) => Err(format!("unexpected `{t}` in `{text}`")),
        }
    }

    /// The value, with `name` resolving every [`Expr::Name`].
    pub fn eval(&self, name: &mut dyn FnMut(&str) -> Result<f64, String>) -> Result<f64, String> {
        Ok(match self {
            Expr::Num(v) => *v,
            Expr::Name(n) => name(n)?,
            Expr::Negate(a) => -a.eval(name)?,
            Expr::Binary(op, a, b) => {
                let (a, b) = (a.eval(name)?, b.eval(name)?);
                match op {
                    '+' => a + b,
                    '-' => a - b,
                    '*' => a * b,
                    _ => a / b,
                }
            }
            Expr::Compare(op, a, b) => {
                let (a, b) = (a.eval(name)?, b.eval(name)?);
                let holds = match op.as_str() {
                    "<" => a < b,
                    "<=" => a <= b,
                    ">" => a > b,
                    ">=" => a >= b,
                    "==" => a == b,
                    _ => a != b,
                };
                f64::from(u8::from(holds))
            }
            Expr::Call(f, args) => {
                let v: Vec<f64> = args
                    .iter()
                    .map(|a| a.eval(name))
                    .collect::<Result<_, _>>()?;
                match (f.as_str(), v.as_slice()) {
                    ("min", [a, b]) => a.min(*b),
                    ("max", [a, b]) => a.max(*b),
                    ("ceil", [a]) => a.ceil(),
                    ("floor", [a]) => a.floor(),
                    ("select", [f, t, c]) => {
                        if *c != 0.0 {
                            *t
                        } else {
                            *f
                        }
                    }
                    _ => return Err(format!("unknown function `{f}` of {} argument(s)", v.len())),
                }
            }
        })
    }

    /// Every name the expression uses.
    pub fn names(&self) -> Vec<&str> {
        match self {
            Expr::Num(_) => Vec::new(),
            Expr::Name(n) => vec![n.as_str()],
            Expr::Negate(a) => a.names(),
            Expr::Binary(_, a, b) | Expr::Compare(_, a, b) => {
                let mut v = a.names();
                v.extend(b.names());
                v
            }
            Expr::Call(_, args) => args.iter().flat_map(Expr::names).collect(),
        }
    }
}

fn tokenize(text: &str) -> Result<Vec<String>, String> {
    let mut tokens = Vec::new();
    let chars: Vec<char> = text.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c.is_whitespace() {
            i += 1;
        } else if c.is_ascii_alphanumeric() || c == '_' || c == '.' {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_alphanumeric() || "_.".contains(chars[i])) {
                i += 1;
            }
            tokens.push(chars[start..i].iter().collect());
        } else if "<>=!".contains(c) {
            let two = chars.get(i + 1) == Some(&'=');
            let end = if two { i + 2 } else { i + 1 };
            let op: String = chars[i..end].iter().collect();
            if op == "=" || op == "!" {
                return Err(format!("unknown operator `{op}` in `{text}`"));
            }
            tokens.push(op);
            i = end;
        } else if "+-*/(),".contains(c) {
            tokens.push(c.to_string());
            i += 1;
        } else {
            return Err(format!("unexpected `{c}` in `{text}`"));
        }
    }
    Ok(tokens)
}

struct Parser {
    tokens: Vec<String>,
    at: usize,
}

impl Parser {
    fn peek(&self) -> Option<&str> {
        self.tokens.get(self.at).map(String::as_str)
    }

    fn next(&mut self) -> Result<String, String> {
        let t = self
            .tokens
            .get(self.at)
            .cloned()
            .ok_or("unexpected end of expression")?;
        self.at += 1;
        Ok(t)
    }

    fn expect(&mut self, token: &str) -> Result<(), String> {
        match self.next()? {
            t if t == token => Ok(()),
            t => Err(format!("expected `{token}`, found `{t}`")),
        }
    }

    fn comparison(&mut self) -> Result<Expr, String> {
        let a = self.sum()?;
        match self.peek() {
            Some(op @ ("<" | "<=" | ">" | ">=" | "==" | "!=")) => {
                let op = op.to_string();
                self.at += 1;
                Ok(Expr::Compare(op, Box::new(a), Box::new(self.sum()?)))
            }
            _ => Ok(a),
        }
    }

    fn sum(&mut self) -> Result<Expr, String> {
        let mut a = self.product()?;
        while let Some(op @ ("+" | "-")) = self.peek() {
            let op = op.chars().next().unwrap_or('+');
            self.at += 1;
            a = Expr::Binary(op, Box::new(a), Box::new(self.product()?));
        }
        Ok(a)
    }

    fn product(&mut self) -> Result<Expr, String> {
        let mut a = self.unary()?;
        while let Some(op @ ("*" | "/")) = self.peek() {
            let op = op.chars().next().unwrap_or('*');
            self.at += 1;
            a = Expr::Binary(op, Box::new(a), Box::new(self.unary()?));
        }
        Ok(a)
    }

    fn unary(&mut self) -> Result<Expr, String> {
        if self.peek() == Some("-") {
            self.at += 1;
            return Ok(Expr::Negate(Box::new(self.unary()?)));
        }
        self.primary()
    }

    fn primary(&mut self) -> Result<Expr, String> {
        let t = self.next()?;
        if t == "(" {
            let e = self.comparison()?;
            self.expect(")")?;
            return Ok(e);
        }
        if let Ok(v) = t.parse::<f64>() {
            return Ok(Expr::Num(v));
        }
        let starts_like_name = t.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_');
        if !starts_like_name {
            return Err(format!("expected a number or a name, found `{t}`"));
        }
        if self.peek() != Some("(") {
            return Ok(Expr::Name(t));
        }
        self.at += 1;
        let mut args = Vec::new();
        if self.peek() != Some(")") {
            loop {
                args.push(self.comparison()?);
                if self.peek() == Some(",") {
                    self.at += 1;
                } else {
                    break;
                }
            }
        }
        self.expect(")")?;
        Ok(Expr::Call(t, args))
    }
}

#[cfg(test)]
mod tests {
    use super::Expr;

    fn eval(text: &str) -> f64 {
        let mut names = |n: &str| match n {
            "WG_SIZE" => Ok(128.0),
            "params.radius" => Ok(3.0),
            "l.mip_levels" => Ok(5.0),
            other => Err(format!("unknown `{other}`")),
        };
        Expr::parse(text)
            .and_then(|e| e.eval(&mut names))
            .unwrap_or_else(|e| panic!("{text}: {e}"))
    }

    #[test]
    fn precedence_calls_and_names() {
        assert_eq!(eval("WG_SIZE + 2 * params.radius"), 134.0);
        assert_eq!(
            eval("(2 * params.radius + 1) * (2 * params.radius + 1)"),
            49.0
        );
        assert_eq!(eval("-2 + 10 / 4"), 0.5);
        assert_eq!(eval("select(4, 8 * max(0, 1), l.mip_levels > 1)"), 8.0);
        assert_eq!(eval("select(4, 8, l.mip_levels <= 1)"), 4.0);
        assert_eq!(eval("ceil(17 / 4) + floor(2.5) + min(1, 2)"), 8.0);
    }

    #[test]
    fn mistakes_are_named() {
        for bad in ["1 +", "(1", "1 = 2", "foo(1)", "unknown", "2 $ 3", "1 2"] {
            let r = Expr::parse(bad).and_then(|e| e.eval(&mut |n| Err(format!("unknown `{n}`"))));
            assert!(r.is_err(), "`{bad}` was accepted");
        }
    }
}
