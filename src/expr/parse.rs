//! Expression text to a syntax tree, with the position of every name.
//!
//! The grammar, loosest first (`-x^2` is `-(x^2)`, `2^-1` is a half, `^`
//! groups to the right):
//!
//! ```text
//! sum     = product (("+" | "-") product)*
//! product = unary (("*" | "/") unary)*
//! unary   = ("-" | "+") unary | power
//! power   = atom ("^" unary)?
//! atom    = number | name | name "(" sum ("," sum)* ")" | "(" sum ")"
//! ```
//!
//! Errors carry the character position they point at, so that the scene's
//! error can put a caret under it.

/// The largest nesting of parentheses, calls and operators accepted: deep
/// enough for any formula, shallow enough that no input exhausts the stack.
pub const MAX_DEPTH: usize = 64;

/// The longest expression accepted, in bytes.
pub const MAX_LENGTH: usize = 10_000;

/// A binary operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Binary {
    /// `a + b`
    Add,
    /// `a - b`
    Sub,
    /// `a * b`
    Mul,
    /// `a / b`
    Div,
    /// `a ^ b`
    Pow,
}

/// A parsed expression. Names are not resolved yet.
#[derive(Debug, Clone, PartialEq)]
pub enum Ast {
    /// A number literal.
    Number(f64),
    /// A name, and the character position it starts at.
    Name(String, usize),
    /// `-a`
    Neg(Box<Ast>),
    /// `a op b`
    Binary(Binary, Box<Ast>, Box<Ast>),
    /// `f(a, ...)`, with the position of `f`.
    Call(String, Vec<Ast>, usize),
}

/// Why a text is not an expression, and the character it points at.
#[derive(Debug, Clone, PartialEq)]
pub struct ParseError {
    /// Character position (0-based) of the offending token.
    pub at: usize,
    /// What is wrong there.
    pub message: String,
}

/// Parse `text` as one expression.
pub fn parse(text: &str) -> Result<Ast, ParseError> {
    if text.len() > MAX_LENGTH {
        return Err(ParseError {
            at: 0,
            message: format!(
                "the expression is {} bytes long, more than the {MAX_LENGTH} accepted",
                text.len()
            ),
        });
    }
    let mut parser = Parser {
        tokens: tokens(text)?,
        next: 0,
        depth: 0,
    };
    let ast = parser.sum()?;
    match parser.peek() {
        (Token::End, _) => Ok(ast),
        (token, at) => Err(ParseError {
            at,
            message: format!(
                "unexpected {} after a complete expression",
                token.describe()
            ),
        }),
    }
}

#[derive(Debug, Clone, PartialEq)]
enum Token {
    Number(f64),
    Name(String),
    Symbol(char),
    End,
}

impl Token {
    fn describe(&self) -> String {
        match self {
            Token::Number(x) => format!("number {x}"),
            Token::Name(n) => format!("name `{n}`"),
            Token::Symbol(c) => format!("`{c}`"),
            Token::End => "end of the expression".into(),
        }
    }
}

/// The tokens of `text`, each with its character position.
fn tokens(text: &str) -> Result<Vec<(Token, usize)>, ParseError> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let start = i;
        if c.is_whitespace() {
            i += 1;
        } else if c.is_ascii_digit() || c == '.' {
            while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
                i += 1;
            }
            // An exponent: e or E, an optional sign, digits.
            if i < chars.len() && (chars[i] == 'e' || chars[i] == 'E') {
                let mut j = i + 1;
                if j < chars.len() && (chars[j] == '+' || chars[j] == '-') {
                    j += 1;
                }
                if j < chars.len() && chars[j].is_ascii_digit() {
                    i = j;
                    while i < chars.len() && chars[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let literal: String = chars[start..i].iter().collect();
            let value = literal.parse::<f64>().map_err(|_| ParseError {
                at: start,
                message: format!("`{literal}` is not a number"),
            })?;
            out.push((Token::Number(value), start));
        } else if c.is_alphabetic() || c == '_' {
            while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            out.push((Token::Name(chars[start..i].iter().collect()), start));
        } else if "+-*/^(),".contains(c) {
            out.push((Token::Symbol(c), start));
            i += 1;
        } else {
            return Err(ParseError {
                at: start,
                message: format!("unexpected character `{c}`"),
            });
        }
    }
    out.push((Token::End, chars.len()));
    Ok(out)
}

struct Parser {
    tokens: Vec<(Token, usize)>,
    next: usize,
    depth: usize,
}

impl Parser {
    fn peek(&self) -> (Token, usize) {
        self.tokens[self.next].clone()
    }

    fn advance(&mut self) -> (Token, usize) {
        let token = self.peek();
        if token.0 != Token::End {
            self.next += 1;
        }
        token
    }

    fn eat(&mut self, symbol: char) -> bool {
        if self.peek().0 == Token::Symbol(symbol) {
            self.next += 1;
            true
        } else {
            false
        }
    }

    /// Enter one more level of nesting, refusing past [`MAX_DEPTH`].
    fn deeper(&mut self) -> Result<(), ParseError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(ParseError {
                at: self.peek().1,
                message: format!("the expression nests deeper than {MAX_DEPTH} levels"),
            });
        }
        Ok(())
    }

    fn sum(&mut self) -> Result<Ast, ParseError> {
        self.deeper()?;
        let mut left = self.product()?;
        loop {
            let op = if self.eat('+') {
                Binary::Add
            } else if self.eat('-') {
                Binary::Sub
            } else {
                break;
            };
            let right = self.product()?;
            left = Ast::Binary(op, Box::new(left), Box::new(right));
        }
        self.depth -= 1;
        Ok(left)
    }

    fn product(&mut self) -> Result<Ast, ParseError> {
        let mut left = self.unary()?;
        loop {
            let op = if self.eat('*') {
                Binary::Mul
            } else if self.eat('/') {
                Binary::Div
            } else {
                break;
            };
            let right = self.unary()?;
            left = Ast::Binary(op, Box::new(left), Box::new(right));
        }
        Ok(left)
    }

    fn unary(&mut self) -> Result<Ast, ParseError> {
        self.deeper()?;
        let ast = if self.eat('-') {
            Ast::Neg(Box::new(self.unary()?))
        } else if self.eat('+') {
            self.unary()?
        } else {
            self.power()?
        };
        self.depth -= 1;
        Ok(ast)
    }

    fn power(&mut self) -> Result<Ast, ParseError> {
        let base = self.atom()?;
        if self.eat('^') {
            let exponent = self.unary()?;
            return Ok(Ast::Binary(Binary::Pow, Box::new(base), Box::new(exponent)));
        }
        Ok(base)
    }

    fn atom(&mut self) -> Result<Ast, ParseError> {
        match self.advance() {
            (Token::Number(x), _) => Ok(Ast::Number(x)),
            (Token::Name(name), at) => {
                if !self.eat('(') {
                    return Ok(Ast::Name(name, at));
                }
                let mut args = vec![self.sum()?];
                while self.eat(',') {
                    args.push(self.sum()?);
                }
                self.close(at)?;
                Ok(Ast::Call(name, args, at))
            }
            (Token::Symbol('('), at) => {
                let inner = self.sum()?;
                self.close(at)?;
                Ok(inner)
            }
            (token, at) => Err(ParseError {
                at,
                message: format!(
                    "expected a number, a name or `(`, found {}",
                    token.describe()
                ),
            }),
        }
    }

    /// The `)` closing what opened at `open`.
    fn close(&mut self, open: usize) -> Result<(), ParseError> {
        if self.eat(')') {
            return Ok(());
        }
        let (token, at) = self.peek();
        Err(ParseError {
            at,
            message: format!(
                "expected `)` closing the `(` at character {}, found {}",
                open + 1,
                token.describe()
            ),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn name(n: &str, at: usize) -> Box<Ast> {
        Box::new(Ast::Name(n.into(), at))
    }

    #[test]
    fn unary_minus_binds_looser_than_power_and_power_groups_right() {
        assert_eq!(
            parse("-x^2").unwrap(),
            Ast::Neg(Box::new(Ast::Binary(
                Binary::Pow,
                name("x", 1),
                Box::new(Ast::Number(2.0))
            )))
        );
        assert_eq!(
            parse("a^b^c").unwrap(),
            Ast::Binary(
                Binary::Pow,
                name("a", 0),
                Box::new(Ast::Binary(Binary::Pow, name("b", 2), name("c", 4)))
            )
        );
    }

    #[test]
    fn products_bind_tighter_than_sums_and_group_left() {
        assert_eq!(
            parse("a - b - c * d").unwrap(),
            Ast::Binary(
                Binary::Sub,
                Box::new(Ast::Binary(Binary::Sub, name("a", 0), name("b", 4))),
                Box::new(Ast::Binary(Binary::Mul, name("c", 8), name("d", 12)))
            )
        );
    }

    #[test]
    fn numbers_with_exponents_and_calls_with_arguments() {
        assert_eq!(
            parse("atan2(1.5e-3, 2E2)").unwrap(),
            Ast::Call(
                "atan2".into(),
                vec![Ast::Number(1.5e-3), Ast::Number(200.0)],
                0
            )
        );
    }

    #[test]
    fn errors_point_at_the_character() {
        let e = parse("v + * 2").unwrap_err();
        assert_eq!(e.at, 4, "{e:?}");
        let e = parse("sin(x").unwrap_err();
        assert_eq!(e.at, 5, "{e:?}");
        assert!(e.message.contains("closing"), "{e:?}");
        let e = parse("x $ y").unwrap_err();
        assert_eq!(e.at, 2);
        let e = parse("x y").unwrap_err();
        assert_eq!(e.at, 2);
        assert!(parse("").is_err());
        assert!(parse("1..2").is_err());
    }

    #[test]
    fn nesting_and_length_are_bounded() {
        let deep = "(".repeat(MAX_DEPTH + 1) + "1" + &")".repeat(MAX_DEPTH + 1);
        assert!(parse(&deep).unwrap_err().message.contains("nests"));
        let minus = "-".repeat(100_000 / 2) + "1";
        assert!(parse(&minus).is_err());
        let ok = "(".repeat(20) + "1" + &")".repeat(20);
        assert_eq!(parse(&ok).unwrap(), Ast::Number(1.0));
    }
}
