//! Syntax trees built and rewritten, for the flows a file does not write
//! out: a discontinuous flow's regions (its `sign()` terms fixed to `+1`
//! or `-1`) and its sliding flow, which needs a switching surface's rate
//! along each side's flow (a Lie derivative, differentiated here
//! symbolically so that the result is an expression like any other: Taylor's
//! method and the linear propagator take it as they take the file's).
//!
//! The builders fold what is plainly zero or one (`0 * a`, `a + 0`,
//! `1 * a`), which keeps the derivatives of the usual surfaces (a state, a
//! state minus a constant) as small as a hand would write them.

use crate::expr::Ast;
use crate::expr::parse::Binary;

/// `a + b`.
pub fn add(a: Ast, b: Ast) -> Ast {
    match (a, b) {
        (Ast::Number(x), Ast::Number(y)) => Ast::Number(x + y),
        (Ast::Number(z), other) | (other, Ast::Number(z)) if z == 0.0 => other,
        (a, b) => Ast::Binary(Binary::Add, Box::new(a), Box::new(b)),
    }
}

/// `a - b` (zero where they are the same expression: the rates two sides'
/// flows share cancel in a sliding flow).
pub fn sub(a: Ast, b: Ast) -> Ast {
    if same(&a, &b) {
        return Ast::Number(0.0);
    }
    match (a, b) {
        (Ast::Number(x), Ast::Number(y)) => Ast::Number(x - y),
        (a, Ast::Number(z)) if z == 0.0 => a,
        (Ast::Number(z), b) if z == 0.0 => neg(b),
        (a, b) => Ast::Binary(Binary::Sub, Box::new(a), Box::new(b)),
    }
}

/// `a * b`.
pub fn mul(a: Ast, b: Ast) -> Ast {
    match (a, b) {
        (Ast::Number(x), Ast::Number(y)) => Ast::Number(x * y),
        (Ast::Number(z), _) | (_, Ast::Number(z)) if z == 0.0 => Ast::Number(0.0),
        (Ast::Number(one), other) | (other, Ast::Number(one)) if one == 1.0 => other,
        (a, b) => Ast::Binary(Binary::Mul, Box::new(a), Box::new(b)),
    }
}

/// `a / b`.
pub fn div(a: Ast, b: Ast) -> Ast {
    match (a, b) {
        (Ast::Number(z), _) if z == 0.0 => Ast::Number(0.0),
        (a, Ast::Number(one)) if one == 1.0 => a,
        (a, b) => Ast::Binary(Binary::Div, Box::new(a), Box::new(b)),
    }
}

/// `-a`.
pub fn neg(a: Ast) -> Ast {
    match a {
        Ast::Number(x) => Ast::Number(-x),
        Ast::Neg(inner) => *inner,
        a => Ast::Neg(Box::new(a)),
    }
}

fn call(name: &str, args: Vec<Ast>) -> Ast {
    Ast::Call(name.to_string(), args, 0)
}

/// The derivative of `ast` with respect to the name `var`, where
/// `varies(name)` says which names are variables (the others, parameters
/// and `pi`, are constants). `Err` with the function that has no
/// derivative there (`sign`, `min`, `max`: not smooth).
pub fn derivative(ast: &Ast, var: &str, varies: &dyn Fn(&str) -> bool) -> Result<Ast, String> {
    let d = |a: &Ast| derivative(a, var, varies);
    Ok(match ast {
        Ast::Number(_) => Ast::Number(0.0),
        Ast::Name(name, _) => Ast::Number(if name == var && varies(name) {
            1.0
        } else {
            0.0
        }),
        Ast::Neg(a) => neg(d(a)?),
        Ast::Binary(op, a, b) => {
            let (a, b) = (a.as_ref(), b.as_ref());
            match op {
                Binary::Add => add(d(a)?, d(b)?),
                Binary::Sub => sub(d(a)?, d(b)?),
                Binary::Mul => add(mul(d(a)?, b.clone()), mul(a.clone(), d(b)?)),
                Binary::Div => {
                    // (a' b - a b') / b^2
                    let top = sub(mul(d(a)?, b.clone()), mul(a.clone(), d(b)?));
                    div(top, mul(b.clone(), b.clone()))
                }
                Binary::Pow => power_derivative(a, b, d(a)?, d(b)?),
            }
        }
        Ast::Call(name, args, _) => {
            let a = || args[0].clone();
            let da = || d(&args[0]);
            match (name.as_str(), args.len()) {
                ("sin", 1) => mul(call("cos", vec![a()]), da()?),
                ("cos", 1) => neg(mul(call("sin", vec![a()]), da()?)),
                ("tan", 1) => {
                    let c = call("cos", vec![a()]);
                    div(da()?, mul(c.clone(), c))
                }
                ("asin", 1) | ("acos", 1) => {
                    let root = call("sqrt", vec![sub(Ast::Number(1.0), mul(a(), a()))]);
                    let d = div(da()?, root);
                    if name == "acos" { neg(d) } else { d }
                }
                ("atan", 1) => div(da()?, add(Ast::Number(1.0), mul(a(), a()))),
                ("sinh", 1) => mul(call("cosh", vec![a()]), da()?),
                ("cosh", 1) => mul(call("sinh", vec![a()]), da()?),
                ("tanh", 1) => {
                    let c = call("cosh", vec![a()]);
                    div(da()?, mul(c.clone(), c))
                }
                ("exp", 1) => mul(call("exp", vec![a()]), da()?),
                ("log", 1) => div(da()?, a()),
                ("sqrt", 1) => div(da()?, mul(Ast::Number(2.0), call("sqrt", vec![a()]))),
                ("abs", 1) => {
                    let da = da()?;
                    if da == Ast::Number(0.0) {
                        da
                    } else {
                        // |a|' = a' a / |a|: not at a = 0, where |a| has no
                        // derivative (a surface's rate is asked away from it).
                        div(mul(da, a()), call("abs", vec![a()]))
                    }
                }
                ("atan2", 2) | ("hypot", 2) | ("pow", 2) => {
                    let (y, x) = (args[0].clone(), args[1].clone());
                    let (dy, dx) = (d(&args[0])?, d(&args[1])?);
                    match name.as_str() {
                        // atan2(y, x)' = (x y' - y x') / (x^2 + y^2)
                        "atan2" => div(
                            sub(mul(x.clone(), dy), mul(y.clone(), dx)),
                            add(mul(x.clone(), x), mul(y.clone(), y)),
                        ),
                        // hypot(a, b)' = (a a' + b b') / hypot(a, b)
                        "hypot" => div(
                            add(mul(y.clone(), dy), mul(x.clone(), dx)),
                            call("hypot", vec![y, x]),
                        ),
                        _ => power_derivative(&y, &x, dy, dx),
                    }
                }
                _ => {
                    let da: Result<Vec<Ast>, String> = args.iter().map(d).collect();
                    if da?.iter().all(|x| *x == Ast::Number(0.0)) {
                        Ast::Number(0.0)
                    } else {
                        return Err(format!(
                            "`{name}` has no derivative where it switches, and a switching \
                             surface's rate needs one"
                        ));
                    }
                }
            }
        }
    })
}

/// `(a^b)'`: `b a^(b - 1) a'` for a constant exponent, `a^b (b' log a + b
/// a' / a)` otherwise.
fn power_derivative(a: &Ast, b: &Ast, da: Ast, db: Ast) -> Ast {
    let pow = |x: Ast, y: Ast| Ast::Binary(Binary::Pow, Box::new(x), Box::new(y));
    if db == Ast::Number(0.0) {
        let lower = sub(b.clone(), Ast::Number(1.0));
        return mul(mul(b.clone(), pow(a.clone(), lower)), da);
    }
    let inner = add(
        mul(db, call("log", vec![a.clone()])),
        div(mul(b.clone(), da), a.clone()),
    );
    mul(pow(a.clone(), b.clone()), inner)
}

/// What can be told of an expression's sign from its form alone, whatever
/// its names' values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Sign {
    Positive,
    NonNegative,
    Negative,
    NonPositive,
    Unknown,
}

impl Sign {
    fn flip(self) -> Sign {
        match self {
            Sign::Positive => Sign::Negative,
            Sign::NonNegative => Sign::NonPositive,
            Sign::Negative => Sign::Positive,
            Sign::NonPositive => Sign::NonNegative,
            Sign::Unknown => Sign::Unknown,
        }
    }

    fn add(self, other: Sign) -> Sign {
        use Sign::*;
        match (self, other) {
            (Positive, Positive | NonNegative) | (NonNegative, Positive) => Positive,
            (NonNegative, NonNegative) => NonNegative,
            (Negative, Negative | NonPositive) | (NonPositive, Negative) => Negative,
            (NonPositive, NonPositive) => NonPositive,
            _ => Unknown,
        }
    }

    fn mul(self, other: Sign) -> Sign {
        use Sign::*;
        let strict = |s: Sign| matches!(s, Positive | Negative);
        let positive = |s: Sign| matches!(s, Positive | NonNegative);
        let negative = |s: Sign| matches!(s, Negative | NonPositive);
        if self == Unknown || other == Unknown {
            return Unknown;
        }
        let same = (positive(self) && positive(other)) || (negative(self) && negative(other));
        match (same, strict(self) && strict(other)) {
            (true, true) => Positive,
            (true, false) => NonNegative,
            (false, true) => Negative,
            (false, false) => NonPositive,
        }
    }
}

fn sign(ast: &Ast) -> Sign {
    match ast {
        Ast::Number(x) if *x > 0.0 => Sign::Positive,
        Ast::Number(x) if *x < 0.0 => Sign::Negative,
        Ast::Number(x) if *x == 0.0 => Sign::NonNegative,
        Ast::Neg(a) => sign(a).flip(),
        Ast::Binary(Binary::Add, a, b) => sign(a).add(sign(b)),
        Ast::Binary(Binary::Sub, a, b) => sign(a).add(sign(b).flip()),
        Ast::Binary(Binary::Mul, a, b) => sign(a).mul(sign(b)),
        // An even whole power is never negative.
        Ast::Binary(Binary::Pow, a, b) => match b.as_ref() {
            Ast::Number(n) if n.fract() == 0.0 && n.rem_euclid(2.0) == 0.0 => {
                if matches!(sign(a), Sign::Positive | Sign::Negative) {
                    Sign::Positive
                } else {
                    Sign::NonNegative
                }
            }
            _ => Sign::Unknown,
        },
        Ast::Call(f, _, _) => match f.as_str() {
            "exp" | "cosh" => Sign::Positive,
            "abs" | "sqrt" | "hypot" => Sign::NonNegative,
            _ => Sign::Unknown,
        },
        _ => Sign::Unknown,
    }
}

/// Whether `ast` can never be zero, whatever its names' values, by its
/// form alone (`x^2 + 1`, `exp(v) + 2`, `-(x^2) - 1`): a guard that never
/// crosses zero.
pub fn never_zero(ast: &Ast) -> bool {
    matches!(sign(ast), Sign::Positive | Sign::Negative)
}

/// `ast` as an expression of the constants alone, where it is a polynomial
/// whose variables cancel (`(x2 + 1) - (x2 - 1)`: the denominator of a
/// sliding flow whose sides differ by a constant): its variables set to
/// zero, which a polynomial that does not depend on them allows. `None`
/// where a variable remains, or sits under a quotient or a function, whose
/// value at zero need not be the expression's.
pub fn constant(ast: &Ast, variables: &[&str]) -> Option<Ast> {
    let varies = |name: &str| variables.contains(&name);
    fn reads(ast: &Ast, varies: &dyn Fn(&str) -> bool) -> bool {
        match ast {
            Ast::Number(_) => false,
            Ast::Name(name, _) => varies(name),
            Ast::Neg(a) => reads(a, varies),
            Ast::Binary(_, a, b) => reads(a, varies) || reads(b, varies),
            Ast::Call(_, args, _) => args.iter().any(|a| reads(a, varies)),
        }
    }
    fn at_zero(ast: &Ast, varies: &dyn Fn(&str) -> bool) -> Option<Ast> {
        if !reads(ast, varies) {
            return Some(ast.clone());
        }
        if let Ast::Binary(Binary::Sub, a, b) = ast
            && same(a, b)
        {
            return Some(Ast::Number(0.0));
        }
        Some(match ast {
            Ast::Name(..) => Ast::Number(0.0),
            Ast::Neg(a) => neg(at_zero(a, varies)?),
            Ast::Binary(Binary::Add, a, b) => add(at_zero(a, varies)?, at_zero(b, varies)?),
            Ast::Binary(Binary::Sub, a, b) => sub(at_zero(a, varies)?, at_zero(b, varies)?),
            Ast::Binary(Binary::Mul, a, b) => mul(at_zero(a, varies)?, at_zero(b, varies)?),
            _ => return None,
        })
    }
    for v in variables {
        if !matches!(derivative(ast, v, &varies).ok()?, Ast::Number(z) if z == 0.0) {
            return None;
        }
    }
    at_zero(ast, &varies)
}

/// `ast` with every `sign(h)` replaced by the number `value(h)` gives, and
/// every `abs(h)` of the same `h` by `value(h) h` (`None` leaves them): a
/// region's flow, smooth in the region (`abs(v - vb)` of a friction law
/// whose surface is `v - vb` is then no switch of its own).
pub fn fix_signs(ast: &Ast, value: &dyn Fn(&Ast) -> Option<f64>) -> Ast {
    let fix = |a: &Ast| fix_signs(a, value);
    match ast {
        Ast::Number(_) | Ast::Name(..) => ast.clone(),
        Ast::Neg(a) => neg(fix(a)),
        Ast::Binary(op, a, b) => Ast::Binary(*op, Box::new(fix(a)), Box::new(fix(b))),
        Ast::Call(name, args, at) if name == "sign" && args.len() == 1 => match value(&args[0]) {
            Some(v) => Ast::Number(v),
            None => Ast::Call(name.clone(), vec![fix(&args[0])], *at),
        },
        Ast::Call(name, args, at) if name == "abs" && args.len() == 1 => match value(&args[0]) {
            Some(v) => mul(Ast::Number(v), fix(&args[0])),
            None => Ast::Call(name.clone(), vec![fix(&args[0])], *at),
        },
        Ast::Call(name, args, at) => Ast::Call(name.clone(), args.iter().map(fix).collect(), *at),
    }
}

/// The arguments of the `sign()` calls in `ast`, each once (the same
/// expression written twice is one surface), in the order they appear;
/// with the character each was called at.
pub fn sign_arguments(ast: &Ast, out: &mut Vec<(Ast, usize)>) {
    match ast {
        Ast::Number(_) | Ast::Name(..) => {}
        Ast::Neg(a) => sign_arguments(a, out),
        Ast::Binary(_, a, b) => {
            sign_arguments(a, out);
            sign_arguments(b, out);
        }
        Ast::Call(name, args, at) => {
            if name == "sign" && args.len() == 1 {
                if !out.iter().any(|(h, _)| same(h, &args[0])) {
                    out.push((args[0].clone(), *at));
                }
            } else {
                args.iter().for_each(|a| sign_arguments(a, out));
            }
        }
    }
}

/// Whether two trees are the same expression (names compared without the
/// positions they were written at).
pub fn same(a: &Ast, b: &Ast) -> bool {
    match (a, b) {
        (Ast::Number(x), Ast::Number(y)) => x == y,
        (Ast::Name(x, _), Ast::Name(y, _)) => x == y,
        (Ast::Neg(x), Ast::Neg(y)) => same(x, y),
        (Ast::Binary(o, a1, b1), Ast::Binary(p, a2, b2)) => o == p && same(a1, a2) && same(b1, b2),
        (Ast::Call(f, x, _), Ast::Call(g, y, _)) => {
            f == g && x.len() == y.len() && x.iter().zip(y).all(|(a, b)| same(a, b))
        }
        _ => false,
    }
}

/// `ast` as text, with no more parentheses than its operators need: what
/// the log and the mode names call a switching surface.
pub fn text(ast: &Ast) -> String {
    /// The precedence of the loosest operator at the top of a tree.
    fn level(ast: &Ast) -> u8 {
        match ast {
            Ast::Binary(Binary::Add | Binary::Sub, ..) => 1,
            Ast::Binary(Binary::Mul | Binary::Div, ..) => 2,
            Ast::Neg(_) => 3,
            Ast::Binary(Binary::Pow, ..) => 4,
            Ast::Number(x) if *x < 0.0 => 3,
            _ => 5,
        }
    }
    let wrap = |a: &Ast, at_least: u8| {
        if level(a) < at_least {
            format!("({})", text(a))
        } else {
            text(a)
        }
    };
    match ast {
        Ast::Number(x) => format!("{x}"),
        Ast::Name(name, _) => name.clone(),
        Ast::Neg(a) => format!("-{}", wrap(a, 4)),
        Ast::Binary(op, a, b) => {
            let (symbol, left, right) = match op {
                Binary::Add => ("+", 1, 1),
                Binary::Sub => ("-", 1, 2),
                Binary::Mul => ("*", 2, 2),
                Binary::Div => ("/", 2, 3),
                Binary::Pow => ("^", 5, 4),
            };
            format!("{} {symbol} {}", wrap(a, left), wrap(b, right))
        }
        Ast::Call(name, args, _) => {
            let args: Vec<String> = args.iter().map(text).collect();
            format!("{name}({})", args.join(", "))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::parse;

    fn eval(ast: &Ast, x: f64) -> f64 {
        let scope = crate::expr::Scope {
            inputs: vec!["x".into()],
            constants: vec![("c".into(), 0.7)],
        };
        let tape = crate::expr::Tape::compile(&[ast], &scope).unwrap();
        tape.eval1(&[x])
    }

    #[test]
    fn a_sign_fixed_by_its_form_is_told() {
        for text in [
            "x^2 + 1",
            "exp(v) + 2",
            "-(x^2) - 1",
            "abs(x) + 0.5",
            "x^4 * 3 + cosh(t)",
        ] {
            assert!(never_zero(&parse(text).unwrap()), "{text}");
        }
        for text in [
            "x^2 - 1",
            "x + 1",
            "sqrt(x)",
            "x^3 + 1",
            "c * x^2 + 1",
            "x^2 * y^2",
        ] {
            assert!(!never_zero(&parse(text).unwrap()), "{text}");
        }
    }

    #[test]
    fn a_polynomial_whose_variables_cancel_is_a_constant() {
        let constant_of = |text: &str| constant(&parse(text).unwrap(), &["x", "t"]);
        let two = constant_of("(c * x + 1 + t) - (c * x - 1 + t)").unwrap();
        assert_eq!(eval(&two, 0.37), 2.0);
        let scaled = constant_of("-(c * 2) * (x - x + 3)").unwrap();
        assert_eq!(eval(&scaled, 5.0), -0.7 * 2.0 * 3.0);
        // A variable that remains, or one under a quotient (x / x is 1, not
        // its value at zero), is not taken.
        assert!(constant_of("(x + 1) - (x - t)").is_none());
        assert!(constant_of("x / x").is_none());
        assert!(constant_of("sin(x) - sin(x) + 1").is_some());
        assert!(constant_of("sin(x) + 1 - sin(x)").is_none());
    }

    #[test]
    fn derivatives_agree_with_differences() {
        let varies = |n: &str| n == "x";
        for text in [
            "x^3 - 2 * x",
            "sin(c * x) * exp(-x)",
            "x / (1 + x^2)",
            "atan2(x, c) + hypot(x, 2) + sqrt(x) + log(x)",
            "tanh(x) - cosh(x) + asin(x / 2) + acos(x / 3) + atan(x)",
            "x^x + pow(x, 2.5) + abs(x - 3)",
        ] {
            let ast = parse(text).unwrap();
            let d = derivative(&ast, "x", &varies).unwrap();
            for x in [0.3, 0.9, 1.7] {
                let h = 1e-6;
                let want = (eval(&ast, x + h) - eval(&ast, x - h)) / (2.0 * h);
                let got = eval(&d, x);
                assert!(
                    (got - want).abs() < 1e-7 * want.abs().max(1.0),
                    "{text} at {x}: {got} vs {want}"
                );
            }
        }
        // Parameters are constants.
        assert_eq!(
            derivative(&parse("c * 4").unwrap(), "x", &varies).unwrap(),
            Ast::Number(0.0)
        );
        // Switches have no derivative.
        assert!(derivative(&parse("min(x, 1)").unwrap(), "x", &varies).is_err());
    }

    #[test]
    fn signs_are_found_once_and_fixed() {
        let ast = parse("-x - 0.1 * sign(v) + sign( v ) * sign(x - 1) + abs(x - 1)").unwrap();
        let mut found = Vec::new();
        sign_arguments(&ast, &mut found);
        let texts: Vec<String> = found.iter().map(|(h, _)| text(h)).collect();
        assert_eq!(texts, ["v", "x - 1"]);
        let fixed = fix_signs(&ast, &|h| Some(if text(h) == "v" { 1.0 } else { -1.0 }));
        assert_eq!(text(&fixed), "-x - 0.1 * 1 + 1 * -1 + -1 * (x - 1)");
    }

    #[test]
    fn text_puts_parentheses_only_where_needed() {
        for (input, shown) in [
            ("a - (b - c)", "a - (b - c)"),
            ("(a - b) - c", "a - b - c"),
            ("a / (b * c)", "a / (b * c)"),
            ("-(a + b) * c", "-(a + b) * c"),
            ("2^(3^x)", "2 ^ 3 ^ x"),
            ("(2^3)^x", "(2 ^ 3) ^ x"),
        ] {
            assert_eq!(text(&parse(input).unwrap()), shown, "{input}");
        }
    }
}
