//! Compiled series and evaluations against the interpreter's, bit for bit,
//! and against closed forms. On x86-64 the portable back end (Cranelift,
//! aarch64's) is held to the same bits beside the hand-assembled one.

use super::*;
use crate::engine::step::taylor_method::MAX_ORDER;
use crate::expr::recurrences::Series;
use crate::expr::recurrences::tests::tape;
use crate::expr::tape::Op;

/// Both series of `texts` from `x0`, bit for bit, at a few orders.
fn same_as_interpreted(texts: &[&str], inputs: &[&str], x0: &[f64]) {
    let t = tape(texts, inputs);
    for order in [1, 2, 7, 20, 33] {
        let w = order + 1;
        let mut interpreted = vec![0.0; x0.len() * w];
        Series::default().flow(&t, x0, order, &mut interpreted);
        #[cfg(target_arch = "x86_64")]
        if let Some(portable) = portable::series(&t, x0, order) {
            for (k, (a, b)) in interpreted.iter().zip(&portable).enumerate() {
                assert_eq!(
                    a.to_bits(),
                    b.to_bits(),
                    "{texts:?} at order {order}: coefficient {} of component {}: {a:e} interpreted, {b:e} by Cranelift",
                    k % w,
                    k / w
                );
            }
        } else {
            assert!(
                CompiledFlow::new(&t, order).is_none(),
                "{texts:?} compiles by hand only"
            );
        }
        let compiled = CompiledFlow::new(&t, order);
        if !super::MACHINE_CODE {
            assert!(compiled.is_none());
            return;
        }
        let compiled = compiled.unwrap_or_else(|| panic!("{texts:?} does not compile"));
        let mut out = vec![f64::NAN; x0.len() * w];
        compiled.flow(x0, &mut out);
        for (k, (a, b)) in interpreted.iter().zip(&out).enumerate() {
            assert_eq!(
                a.to_bits(),
                b.to_bits(),
                "{texts:?} at order {order}: coefficient {} of component {}: {a:e} interpreted, {b:e} compiled",
                k % w,
                k / w
            );
        }
    }
}

/// The degrees the compiled sums stop at: the clock's 1, a state driven
/// by it one more, products the sum, anything of a state that is not a
/// polynomial none; and each such coefficient is zero in the series.
#[test]
fn polynomial_states_have_their_degrees() {
    let t = tape(
        &["1", "t", "p * t", "-x + q * cos(2 * t)"],
        &["t", "p", "q", "x"],
    );
    let degree = series::degrees(&t);
    let input = |j: u32| {
        let r = t.ops.iter().position(|op| *op == Op::Input(j)).unwrap();
        degree[r]
    };
    assert_eq!(
        [input(0), input(1), input(2), input(3)],
        [1, 2, 4, usize::MAX]
    );
    let order = 9;
    let mut out = vec![0.0; 4 * (order + 1)];
    Series::default().flow(&t, &[0.5, 0.25, -1.0, 0.3], order, &mut out);
    for (i, d) in [1, 2, 4].into_iter().enumerate() {
        let c = &out[i * (order + 1)..(i + 1) * (order + 1)];
        assert!(
            c[d] != 0.0 && c[d + 1..].iter().all(|&x| x == 0.0),
            "{i}: {c:?}"
        );
    }
}

#[test]
fn every_compiled_instruction_gives_the_interpreters_bits() {
    let xy = ["x", "y"];
    let state = [0.7, -0.4];
    // Sums, a negation, constants on either side, products, quotients.
    same_as_interpreted(&["y", "-x - 2 * x * y"], &xy, &state);
    same_as_interpreted(&["x * c + y", "c * y - x / 3"], &xy, &state);
    same_as_interpreted(&["x / (1 + y^2)", "(x - y) / (2 + x)"], &xy, &state);
    same_as_interpreted(&["1 / (3 + x)", "-y"], &xy, &state);
    // Squares (each pair once, doubled), and a fourth power by squaring.
    same_as_interpreted(&["y^2 - x", "x^2 * y + y^4"], &xy, &state);
    // Functions, with their helper series.
    same_as_interpreted(&["y", "-sin(x)"], &xy, &state);
    same_as_interpreted(&["cos(x + y)", "sin(2 * x) * cos(y)"], &xy, &state);
    same_as_interpreted(&["sinh(x) - y", "cosh(y) * x"], &xy, &state);
    same_as_interpreted(&["exp(-x) * y", "-exp(x * y)"], &xy, &state);
    // A value kept in a register (`x * y`), used again after a function's
    // call has clobbered the registers.
    same_as_interpreted(&["(x * y) * sin(y) + x * y", "x"], &xy, &state);
    // A rate that is an input, or a constant (a clock), or the same
    // register as another's.
    same_as_interpreted(&["y", "x", "1"], &["x", "y", "t"], &[0.2, 0.1, 5.0]);
    same_as_interpreted(&["x * y", "x * y"], &xy, &state);
    // A forced oscillator: the clock inside a function.
    same_as_interpreted(
        &["v", "-x - 0.1 * v + 0.5 * cos(1.3 * t)", "1"],
        &["x", "v", "t"],
        &[0.3, 0.0, 12.5],
    );
    // Polynomials in the step, whose Cauchy sums leave out the terms past
    // their degrees: the clock (degree 1), a state driven by it (p' = t,
    // degree 2) and by that one (q' = p t, degree 4), in products,
    // quotients and functions with states that are not polynomials, and a
    // function of constants (degree 0).
    same_as_interpreted(
        &[
            "1",
            "t",
            "p * t",
            "-x * (1 + q) + exp(-0.1 * t) * sin(p)",
            "x / (2 + t) - cos(3) * x * t * p + sinh(0.5 * t) / (1 + x^2)",
        ],
        &["t", "p", "q", "x", "y"],
        &[1.5, -0.25, 0.125, 0.4, -0.3],
    );
    // A chain of twelve coupled cubic oscillators with a sine: more
    // series than the code has windows into its buffers, so that places
    // past them are reached from the buffers' bases, and windows set
    // again after the sine's call.
    let names: Vec<String> = (0..12).map(|i| format!("x{i}")).collect();
    let rates: Vec<String> = (0..12)
        .map(|i| {
            let (left, right) = (&names[(i + 11) % 12], &names[(i + 1) % 12]);
            let me = &names[i];
            if i == 5 {
                format!("{left} - 2 * {me} + {right} - {me}^3 + 0.1 * sin({left} * {right})")
            } else {
                format!("{left} - 2 * {me} + {right} - {me}^3 + c * {left} * {me}")
            }
        })
        .collect();
    let inputs: Vec<&str> = names.iter().map(String::as_str).collect();
    let texts: Vec<&str> = rates.iter().map(String::as_str).collect();
    let start: Vec<f64> = (0..12).map(|i| 0.1 * (i as f64 - 5.5)).collect();
    same_as_interpreted(&texts, &inputs, &start);
    // Squares of polynomials: their pairs and middle terms past the
    // degree left out.
    same_as_interpreted(
        &["1", "t", "-x + t^2 + p^2 * x + (p * t)^2"],
        &["t", "p", "x"],
        &[1.5, -0.25, 0.4],
    );
}

/// x' = v, v' = -x from (1, 0): x = cos t, v = -sin t, by the compiled
/// series alone.
#[test]
fn the_compiled_oscillator_expands_to_cosine_and_sine() {
    if !super::MACHINE_CODE {
        return;
    }
    let order = 20;
    let flow = CompiledFlow::new(&tape(&["v", "-x"], &["x", "v"]), order).unwrap();
    let mut out = vec![0.0; 2 * (order + 1)];
    flow.flow(&[1.0, 0.0], &mut out);
    let factorial = |k: usize| (1..=k).map(|i| i as f64).product::<f64>();
    for k in 0..=order {
        let (cos, minus_sin) = match k % 4 {
            0 => (1.0, 0.0),
            1 => (0.0, -1.0),
            2 => (-1.0, 0.0),
            _ => (0.0, 1.0),
        };
        assert!(
            (out[k] - cos / factorial(k)).abs() <= 1e-15 / factorial(k),
            "x_{k}"
        );
        assert!(
            (out[order + 1 + k] - minus_sin / factorial(k)).abs() <= 1e-15 / factorial(k),
            "v_{k}"
        );
    }
}

#[test]
fn what_does_not_compile_is_left_to_the_interpreter() {
    let xy = ["x", "y"];
    for texts in [
        ["x^1.5", "y"],
        ["tan(x)", "y"],
        ["atan2(y, x)", "x"],
        ["sqrt(x)", "y"],
    ] {
        assert!(
            CompiledFlow::new(&tape(&texts, &xy), 10).is_none(),
            "{texts:?}"
        );
    }
    // No order 0 (a flow's series has at least its rate) or past the
    // largest.
    let t = tape(&["y", "-x"], &xy);
    assert!(CompiledFlow::new(&t, 0).is_none());
    assert!(CompiledFlow::new(&t, MAX_ORDER + 1).is_none());
    // The cache answers the same for a tape it cannot compile, warmed up
    // or not.
    let flows = CompiledFlows::default();
    let t = tape(&["tan(x)", "y"], &xy);
    assert!((0..=tiered::WARM_UP).all(|_| flows.get(&t, 10).is_none()));
}

/// Threads of a sweep share one compiled flow, each with its own work
/// buffer: the interpreter answers until the flow is warmed up, the
/// compiled code after, and every answer is the same.
#[test]
fn threads_share_a_compiled_flow() {
    let t = tape(&["y", "-x - 2 * x * y"], &["x", "y"]);
    let flows = CompiledFlows::default();
    let order = 12;
    let interpreted = |x: f64| {
        let mut out = vec![0.0; 2 * (order + 1)];
        Series::default().flow(&t, &[x, 0.1], order, &mut out);
        out
    };
    let compiled_calls = std::thread::scope(|s| {
        let threads: Vec<_> = (0..4)
            .map(|i| {
                let (flows, t, interpreted) = (&flows, &t, &interpreted);
                s.spawn(move || {
                    let x = 0.1 * i as f64;
                    let expected = interpreted(x);
                    let mut out = vec![0.0; 2 * (order + 1)];
                    let mut compiled = 0;
                    for _ in 0..tiered::WARM_UP / 4 + 100 {
                        if let Some(code) = flows.get(t, order) {
                            code.flow(&[x, 0.1], &mut out);
                            assert_eq!(out, expected);
                            compiled += 1;
                        }
                    }
                    compiled
                })
            })
            .collect();
        threads.into_iter().map(|t| t.join().unwrap()).sum::<u32>()
    });
    // WARM_UP + 400 calls, the first WARM_UP of them (all threads
    // together) to the interpreter.
    if super::MACHINE_CODE {
        assert_eq!(compiled_calls, 400);
    }
}

/// A tape is interpreted for its first WARM_UP calls and compiled on the
/// next; the answers are the same bits throughout.
#[test]
fn a_tape_is_compiled_once_warmed_up() {
    let t = tape(&["x * y - sin(x)", "exp(y) / (1 + x^2)"], &["x", "y"]);
    let code = CompiledTape::default();
    let mut want = [0.0; 2];
    t.eval_scratch(&[0.4, -0.2], &mut want);
    for call in 0..=tiered::WARM_UP {
        assert_eq!(
            code.compiled(),
            super::MACHINE_CODE && call > tiered::WARM_UP
        );
        let mut out = [f64::NAN; 2];
        code.eval(&t, &[0.4, -0.2], &mut out);
        assert_eq!(out.map(f64::to_bits), want.map(f64::to_bits), "call {call}");
    }
    assert_eq!(code.compiled(), super::MACHINE_CODE);
}

/// Every instruction and every function, evaluated compiled and
/// interpreted, at points inside and outside their domains (a NaN is the
/// interpreter's NaN).
#[test]
fn every_compiled_evaluation_gives_the_interpreters_bits() {
    let t = tape(
        &[
            "-x^2 + y/c - 9.81 * sin(t) + x^1.5 + pow(c, y)",
            "atan2(x, y) + hypot(x, y) + max(x, y) - min(x, y)",
            "exp(-x) * log(c) + sqrt(abs(y)) + cosh(x) - tanh(y) + sinh(t) + tan(x)",
            "asin(x) + acos(y) + atan(y) + cos(x) * sign(y) - 1 / (x - y)",
            "y",
            "2.5",
        ],
        &["x", "y", "t"],
    );
    let code = CompiledTape::default();
    // Warmed up (see `a_tape_is_compiled_once_warmed_up`).
    for _ in 0..tiered::WARM_UP {
        code.eval(&t, &[0.3, -0.7, 2.5], &mut [0.0; 6]);
    }
    for point in [
        [0.3, -0.7, 2.5],
        [-1.5, 0.0, -3.0],
        [0.0, 2.0, 1e3],
        [f64::NAN, 1.0, 0.0],
    ] {
        let mut interpreted = [0.0; 6];
        t.eval_scratch(&point, &mut interpreted);
        let mut compiled = [f64::INFINITY; 6];
        code.eval(&t, &point, &mut compiled);
        #[cfg(target_arch = "x86_64")]
        let portable = portable::eval(&t, &point).expect("every tape compiles");
        #[cfg(not(target_arch = "x86_64"))]
        let portable = compiled;
        for (i, ((a, b), c)) in interpreted.iter().zip(&compiled).zip(&portable).enumerate() {
            for (b, by) in [(b, "compiled"), (c, "by Cranelift")] {
                assert!(
                    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                    "output {i} at {point:?}: {a:e} interpreted, {b:e} {by}"
                );
            }
        }
        // Compiled for real: only the interpreter's fallback would leave
        // this machine's code unexercised.
        assert!(!super::MACHINE_CODE || code.compiled());
    }
}

/// A random smooth expression over `inputs`, at most `depth` deep: sums,
/// products, quotients by positive denominators, small powers, and the
/// functions the compiler lowers, so that every value stays finite for
/// inputs in [-1, 1].
fn expression(inputs: Vec<String>, depth: u32) -> BoxedStrategy<String> {
    let leaf = prop_oneof![
        proptest::sample::select(inputs.clone()),
        (-3.0f64..3.0).prop_map(|c| format!("{c:.3}")),
    ]
    .boxed();
    if depth == 0 {
        return leaf;
    }
    let inner = expression(inputs, depth - 1);
    prop_oneof![
        leaf,
        (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("({a} + {b})")),
        (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("({a} - {b})")),
        (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("({a} * {b})")),
        (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("({a} / (2 + ({b})^2))")),
        (inner.clone(), 2u32..4).prop_map(|(a, k)| format!("({a})^{k}")),
        (
            proptest::sample::select(vec!["sin", "cos", "sinh", "cosh", "exp"]),
            inner.clone()
        )
            .prop_map(|(f, a)| format!("{f}(0.5 * ({a}))")),
        inner.prop_map(|a| format!("-({a})")),
    ]
    .boxed()
}

use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// Random flows of 2 to 16 states (more than the compiled code keeps
    /// in registers, so windows are set again after calls), their
    /// constants, operations and orders drawn at random: compiled, each
    /// Taylor coefficient has the interpreter's bits.
    #[test]
    fn random_flows_compile_to_the_interpreters_bits(
        (texts, x0) in (2usize..=16).prop_flat_map(|n| {
            let inputs: Vec<String> = (0..n).map(|i| format!("x{i}")).collect();
            (
                proptest::collection::vec(expression(inputs, 3), n),
                proptest::collection::vec(-1.0f64..1.0, n),
            )
        })
    ) {
        let inputs: Vec<String> = (0..texts.len()).map(|i| format!("x{i}")).collect();
        let inputs: Vec<&str> = inputs.iter().map(String::as_str).collect();
        let texts: Vec<&str> = texts.iter().map(String::as_str).collect();
        // Where a constant overflows (cosh of (-2.8)^9), infinities meet
        // in sums whose order the two need not share: NaN one way, -inf
        // the other; the engine refuses either. Finite series only.
        let order = 33;
        let mut series = vec![0.0; x0.len() * (order + 1)];
        Series::default().flow(&tape(&texts, &inputs), &x0, order, &mut series);
        prop_assume!(series.iter().all(|c| c.is_finite()));
        same_as_interpreted(&texts, &inputs, &x0);
    }
}

/// The portable back end's code for a tape, run as `CompiledFlow` and
/// the evaluation run theirs.
#[cfg(target_arch = "x86_64")]
mod portable {
    use crate::expr::compiled::cranelift::Emitter;
    use crate::expr::compiled::layout::Layout;
    use crate::expr::compiled::{evaluation, series};
    use crate::expr::tape::Tape;

    /// The series of `t` from `x0` at `order`, if it compiles.
    pub fn series(t: &Tape, x0: &[f64], order: usize) -> Option<Vec<f64>> {
        let w = order + 1;
        let layout = Layout::new(t, w);
        let code = series::lower(Emitter::new(layout.extents(0))?, t, &layout, order)?;
        let mut work = vec![0.0; layout.work(0)];
        let mut out = vec![f64::NAN; t.outputs.len() * w];
        for (i, &x) in x0.iter().enumerate() {
            out[i * w] = x;
        }
        // SAFETY: the buffers have the lengths the layout gives, as
        // `CompiledFlow::flow` sizes them.
        unsafe { code.run(work.as_mut_ptr(), out.as_mut_ptr(), layout.pool.as_ptr()) };
        Some(out)
    }

    /// The outputs of `t` at `inputs`, if it compiles.
    pub fn eval(t: &Tape, inputs: &[f64]) -> Option<Vec<f64>> {
        let layout = Layout::new(t, 1);
        let outputs = t.outputs.len();
        let code = evaluation::lower(Emitter::new(layout.extents(outputs))?, t, &layout)?;
        let mut work = vec![0.0; layout.work(outputs)];
        let mut state = inputs.to_vec();
        // SAFETY: as the evaluation sizes them.
        unsafe { code.run(work.as_mut_ptr(), state.as_mut_ptr(), layout.pool.as_ptr()) };
        Some(work[work.len() - outputs..].to_vec())
    }
}

/// Taylor arithmetic in double-double on the parsed expression, written
/// here apart from the interpreter's recurrences (`recurrences.rs`) and the
/// compiled code: the reference the interpreter's series are held to.
mod reference {
    use crate::expr::parse::{Ast, Binary};
    use twofloat::TwoFloat as D;

    fn times(a: &[D], b: &[D]) -> Vec<D> {
        (0..a.len())
            .map(|k| (0..=k).fold(D::from(0.0), |s, j| s + a[j] * b[k - j]))
            .collect()
    }

    fn over(a: &[D], b: &[D]) -> Vec<D> {
        let mut q: Vec<D> = Vec::with_capacity(a.len());
        for k in 0..a.len() {
            let known = (1..=k).fold(D::from(0.0), |s, j| s + b[j] * q[k - j]);
            q.push((a[k] - known) / b[0]);
        }
        q
    }

    /// `exp(a)`: `e' = a' e`.
    fn exp(a: &[D]) -> Vec<D> {
        let mut e = vec![a[0].exp()];
        for k in 1..a.len() {
            let sum = (1..=k).fold(D::from(0.0), |s, j| s + D::from(j as f64) * a[j] * e[k - j]);
            e.push(sum / D::from(k as f64));
        }
        e
    }

    /// `(sin, cos)` or `(sinh, cosh)` of `a`: `s' = a' c`, `c' = -+ a' s`.
    fn pair(a: &[D], hyperbolic: bool) -> (Vec<D>, Vec<D>) {
        let (mut s, mut c) = if hyperbolic {
            (vec![a[0].sinh()], vec![a[0].cosh()])
        } else {
            (vec![a[0].sin()], vec![a[0].cos()])
        };
        let sign = D::from(if hyperbolic { 1.0 } else { -1.0 });
        for k in 1..a.len() {
            let (mut ds, mut dc) = (D::from(0.0), D::from(0.0));
            for j in 1..=k {
                ds += D::from(j as f64) * a[j] * c[k - j];
                dc += D::from(j as f64) * a[j] * s[k - j];
            }
            s.push(ds / D::from(k as f64));
            c.push(sign * dc / D::from(k as f64));
        }
        (s, c)
    }

    /// The series of `ast` where each input has the series `inputs(name)`.
    pub fn eval(ast: &Ast, inputs: &dyn Fn(&str) -> Vec<D>, n: usize) -> Vec<D> {
        let constant = |c: f64| {
            let mut v = vec![D::from(0.0); n];
            v[0] = D::from(c);
            v
        };
        match ast {
            Ast::Number(c) => constant(*c),
            Ast::Name(name, _) => inputs(name),
            Ast::Neg(a) => eval(a, inputs, n).into_iter().map(|x| -x).collect(),
            Ast::Binary(op, a, b) => {
                let a = eval(a, inputs, n);
                if let (Binary::Pow, Ast::Number(k)) = (op, &**b) {
                    return (1..*k as usize).fold(a.clone(), |p, _| times(&p, &a));
                }
                let b = eval(b, inputs, n);
                match op {
                    Binary::Add => a.iter().zip(&b).map(|(x, y)| *x + *y).collect(),
                    Binary::Sub => a.iter().zip(&b).map(|(x, y)| *x - *y).collect(),
                    Binary::Mul => times(&a, &b),
                    Binary::Div => over(&a, &b),
                    Binary::Pow => panic!("only whole powers here"),
                }
            }
            Ast::Call(f, args, _) => {
                let a = eval(&args[0], inputs, n);
                match f.as_str() {
                    "exp" => exp(&a),
                    "sin" => pair(&a, false).0,
                    "cos" => pair(&a, false).1,
                    "sinh" => pair(&a, true).0,
                    "cosh" => pair(&a, true).1,
                    other => panic!("no reference for {other}"),
                }
            }
        }
    }

    /// The Taylor coefficients to `order` of the flow `x' = f(x)` from
    /// `x0`, by Picard's recurrence `c_(k+1) = f(c)_k / (k + 1)`.
    pub fn flow(asts: &[Ast], names: &[&str], x0: &[f64], order: usize) -> Vec<Vec<D>> {
        let n = order + 1;
        let mut c: Vec<Vec<D>> = x0
            .iter()
            .map(|&x| {
                let mut v = vec![D::from(0.0); n];
                v[0] = D::from(x);
                v
            })
            .collect();
        for k in 0..order {
            let inputs = |name: &str| c[names.iter().position(|m| *m == name).unwrap()].clone();
            let rates: Vec<D> = asts.iter().map(|a| eval(a, &inputs, n)[k]).collect();
            for (component, rate) in c.iter_mut().zip(rates) {
                component[k + 1] = rate / D::from((k + 1) as f64);
            }
        }
        c
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// The interpreter's Taylor coefficients of random flows against the
    /// double-double reference above, to order 12: within 1e-10 of each
    /// coefficient, or of 1e-12 of the largest of its component's where
    /// sums cancel.
    #[test]
    fn random_flows_expand_as_double_double_does(
        (texts, x0) in (2usize..=6).prop_flat_map(|n| {
            let inputs: Vec<String> = (0..n).map(|i| format!("x{i}")).collect();
            (
                proptest::collection::vec(expression(inputs, 3), n),
                proptest::collection::vec(-1.0f64..1.0, n),
            )
        })
    ) {
        let names: Vec<String> = (0..texts.len()).map(|i| format!("x{i}")).collect();
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        let text_refs: Vec<&str> = texts.iter().map(String::as_str).collect();
        let order = 12;
        let mut series = vec![0.0; x0.len() * (order + 1)];
        Series::default().flow(&tape(&text_refs, &names), &x0, order, &mut series);
        prop_assume!(series.iter().all(|c| c.is_finite()));
        let asts: Vec<_> = texts
            .iter()
            .map(|t| crate::expr::parse::parse(t).unwrap())
            .collect();
        let reference = reference::flow(&asts, &names, &x0, order);
        for (i, want) in reference.iter().enumerate() {
            let got = &series[i * (order + 1)..(i + 1) * (order + 1)];
            let largest = want.iter().fold(0.0_f64, |m, w| m.max(f64::from(*w).abs()));
            for (k, (g, w)) in got.iter().zip(want).enumerate() {
                let w = f64::from(*w);
                prop_assert!(
                    (g - w).abs() <= 1e-10 * w.abs() + 1e-12 * largest,
                    "{texts:?} from {x0:?}: coefficient {k} of x{i}: {g:e} interpreted, {w:e} double-double"
                );
            }
        }
    }
}
