//! Following a periodic orbit as a parameter moves: pseudo-arclength
//! continuation, with the bifurcations of impacting orbits found on the
//! way.
//!
//! The unknowns are the orbit's section state (the free components) and
//! the parameter, held by the model as a state that never changes
//! ([`Family::promoted`]), so that the section map's
//! Jacobian has its derivative with respect to the parameter as one more
//! column. From each orbit the branch's tangent (the null vector of `[DP -
//! I | dP/dp]`, oriented as the last) predicts the next, which Newton
//! corrects on the plane orthogonal to the tangent: the branch is followed
//! through folds, where the parameter turns back. The step grows while
//! Newton converges fast and halves where it does not.
//!
//! Between two orbits, a test function that changes sign marks a
//! bifurcation, located by bisection along the chord between them (each
//! trial corrected across it) to 1e-10:
//!
//! - **fold**: a multiplier through +1, `det(DP - I)` (the trivial 0 of
//!   `DP` gives -1 there, a fixed sign);
//! - **period doubling**: a multiplier through -1, `det(DP + I)`;
//! - **torus**: a complex pair through the unit circle, the product of
//!   `|mu|^2 - 1` over the pairs.
//!
//! **Grazing**, the orbit touching a guard tangentially: the impact speed
//! is watched along the branch, and where it falls to zero within the
//! next step the grazing parameter is solved for directly
//! ([`crate::analysis::orbit::grazing`]); the branch of impacting orbits
//! ends there, labelled, saying on which side they exist. A corrector that
//! meets a graze first (a section map that cannot tell whether an event
//! fires), or whose steps shrink to nothing, ends the branch too: at the
//! graze the last three orbits' impact speeds put ahead, labelled where
//! they locate it to 1e-9, else saying how far short it ends.
//!
//! [`Family::promoted`]: crate::engine::Family::promoted

use nalgebra::{DMatrix, DVector};

use crate::analysis::orbit::grazing;
use crate::analysis::orbit::section::{Return, Section};
use crate::analysis::orbit::shooting::{Unknowns, least_squares, multipliers};
use crate::engine::Mode;

/// Newton iterations of a corrector at most.
const CORRECTOR_ITERATIONS: usize = 8;

/// Residual at which a corrector stops, relative to the state's size.
const TOLERANCE: f64 = 1e-11;

/// How far a bifurcation is pinned along the branch, relative to the
/// unknowns' size.
const LOCATE: f64 = 1e-10;

/// What a continuation is asked: the parameter's index among the
/// (promoted) states, where to stop, the step limits.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The parameter's component.
    pub parameter: usize,
    /// Where the parameter is to go.
    pub to: f64,
    /// Orbits at most.
    pub points: usize,
    /// The first and the largest arclength step, relative to the
    /// parameter's range.
    pub step: (f64, f64),
}

/// One orbit of the branch.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// The parameter.
    pub parameter: f64,
    /// The period.
    pub period: f64,
    /// The section state (every component).
    pub state: Vec<f64>,
    /// The multipliers, the trivial 1 first.
    pub multipliers: Vec<(f64, f64)>,
    /// Whether it is stable.
    pub stable: bool,
    /// What happens here: empty, `fold`, `period doubling`, `torus`,
    /// `grazing`, `end`.
    pub label: String,
}

/// The branch, and why it ended.
#[derive(Debug, Clone, PartialEq)]
pub struct Branch {
    /// The orbits in order along the branch (bifurcations among them).
    pub points: Vec<Point>,
    /// Why the branch ended: `reached`, or what stopped it.
    pub ended: String,
}

/// The test functions whose signs mark a bifurcation: `det(DP - I)`,
/// `det(DP + I)`, and the product of `|mu|^2 - 1` over complex pairs
/// (NaN without one); last, how many complex pairs there are.
fn tests(r: &Return, unknowns: &Unknowns) -> [f64; 4] {
    let k = unknowns.free.len();
    let dp = DMatrix::from_fn(k, k, |a, b| {
        r.jacobian[(unknowns.free[a], unknowns.free[b])]
    });
    let identity = DMatrix::<f64>::identity(k, k);
    let fold = (&dp - &identity).determinant();
    let doubling = (&dp + &identity).determinant();
    // Over the complex pairs only: where a pair turns real (or back) the
    // product is not compared (see `push_with_bifurcations`).
    let pairs: Vec<f64> = dp
        .complex_eigenvalues()
        .iter()
        .filter(|z| z.im > 0.0)
        .map(|z| z.norm_sqr() - 1.0)
        .collect();
    let torus = if pairs.is_empty() {
        f64::NAN
    } else {
        pairs.iter().product()
    };
    [fold, doubling, torus, pairs.len() as f64]
}

/// The labels of the test functions, in order.
const LABELS: [&str; 3] = ["fold", "period doubling", "torus"];

/// A solved orbit: its state (all components), the map's return from it,
/// and the tangent of the branch there.
#[derive(Debug, Clone)]
struct Solved {
    x: Vec<f64>,
    back: Return,
}

/// The residual `P(x) - x` (the clock on whole forcing periods) and the
/// augmented Jacobian `[DP - I | dP/dp]` on the free components.
fn system(unknowns: &Unknowns, p: usize, x: &[f64], back: &Return) -> (DVector<f64>, DMatrix<f64>) {
    let r = unknowns.residual(x, &back.state, back.elapsed);
    let k = unknowns.free.len();
    let a = DMatrix::from_fn(k, k + 1, |i, j| {
        let row = unknowns.free[i];
        if j < k {
            back.jacobian[(row, unknowns.free[j])] - if i == j { 1.0 } else { 0.0 }
        } else {
            back.jacobian[(row, p)]
        }
    });
    (r, a)
}

/// `(x_free, p)` of a state.
fn unknown_vector(unknowns: &Unknowns, p: usize, x: &[f64]) -> DVector<f64> {
    DVector::from_iterator(
        unknowns.free.len() + 1,
        unknowns
            .free
            .iter()
            .map(|&i| x[i])
            .chain(std::iter::once(x[p])),
    )
}

/// The state with `(x_free, p)` set from `z`.
fn with_unknowns(unknowns: &Unknowns, p: usize, x: &[f64], z: &DVector<f64>) -> Vec<f64> {
    let mut out = x.to_vec();
    for (k, &i) in unknowns.free.iter().enumerate() {
        out[i] = z[k];
    }
    out[p] = z[unknowns.free.len()];
    out
}

/// The branch's unit tangent at an orbit: `[DP - I | dP/dp] t = 0`,
/// oriented along `previous`.
fn tangent(a: &DMatrix<f64>, previous: &DVector<f64>) -> Option<DVector<f64>> {
    let k = a.nrows();
    let mut m = DMatrix::zeros(k + 1, k + 1);
    m.view_mut((0, 0), (k, k + 1)).copy_from(a);
    m.row_mut(k).copy_from(&previous.transpose());
    let mut rhs = DVector::zeros(k + 1);
    rhs[k] = 1.0;
    let (t, _) = least_squares(&m, &rhs)?;
    let norm = t.norm();
    (norm.is_finite() && norm > 0.0).then(|| t / norm)
}

/// Newton from the state `x` (just after a section event in `mode`) on
/// `P(x) = x` and, with `plane = Some((z0, t))`, `t . (z - z0) = 0`; with
/// `None`, at the parameter `x` has.
fn correct(
    section: &Section,
    unknowns: &Unknowns,
    p: usize,
    mode: Mode,
    x: Vec<f64>,
    plane: Option<(&DVector<f64>, &DVector<f64>)>,
) -> Result<Solved, String> {
    let k = unknowns.free.len();
    let mut x = x;
    for _ in 0..CORRECTOR_ITERATIONS {
        let back = section.map(mode, &x)?;
        if !section.family.same_motion(mode, back.mode) {
            return Err(format!(
                "the orbit returns in mode `{}`, not `{}`",
                section.model.mode_name(back.mode),
                section.model.mode_name(mode)
            ));
        }
        let (r, a) = system(unknowns, p, &x, &back);
        let scale = unknowns.scale(&x).max(x[p].abs());
        let on_plane = plane.map_or(0.0, |(z0, t)| {
            t.dot(&(unknown_vector(unknowns, p, &x) - z0))
        });
        if r.amax() <= TOLERANCE * scale && on_plane.abs() <= TOLERANCE * scale {
            return Ok(Solved { x, back });
        }
        let step = match plane {
            Some((_, t)) => {
                let mut m = DMatrix::zeros(k + 1, k + 1);
                m.view_mut((0, 0), (k, k + 1)).copy_from(&a);
                m.row_mut(k).copy_from(&t.transpose());
                let mut rhs = DVector::zeros(k + 1);
                rhs.rows_mut(0, k).copy_from(&(-&r));
                rhs[k] = -on_plane;
                least_squares(&m, &rhs).map(|(d, _)| d)
            }
            None => least_squares(&a.columns(0, k).into_owned(), &(-&r)).map(|(d, _)| {
                let mut full = DVector::zeros(k + 1);
                full.rows_mut(0, k).copy_from(&d);
                full
            }),
        }
        .ok_or("the Newton matrix is not finite (a graze on the way round?)")?;
        let z = unknown_vector(unknowns, p, &x) + step;
        // The clock is not folded here: the branch's tangent and the
        // corrector's plane are about the unknowns as they move.
        x = with_unknowns(unknowns, p, &x, &z);
        if !x.iter().all(|v| v.is_finite()) {
            return Err("the Newton step left the finite numbers".into());
        }
    }
    Err(format!(
        "Newton did not converge in {CORRECTOR_ITERATIONS} iterations"
    ))
}

/// A point of the branch from a solved orbit.
fn point(unknowns: &Unknowns, p: usize, s: &Solved, label: &str) -> Point {
    let (multipliers, stable) = multipliers(&s.back, unknowns);
    // A forced system's clock as the forcing's phase, in [0, T) as the
    // brute-force diagram's (Newton leaves it anywhere, below zero past
    // a fold).
    let mut state = s.x.clone();
    unknowns.fold_clock(&mut state);
    Point {
        parameter: s.x[p],
        period: s.back.elapsed,
        state,
        multipliers,
        stable,
        label: label.to_string(),
    }
}

/// Pin the bifurcation whose test function `which` changes sign between
/// the orbits `a` and `b` by bisection along the branch: each trial an
/// orbit corrected on the plane across the chord from `a` to `b` at a
/// fraction of it (the parameter alone would not do at a fold, where the
/// branch turns back in it), until the chord's piece is below 1e-10 of
/// the unknowns' size.
fn locate(
    section: &Section,
    unknowns: &Unknowns,
    p: usize,
    mode: Mode,
    (a, b): (&Solved, &Solved),
    which: usize,
) -> Option<Solved> {
    let sign = |s: &Solved| tests(&s.back, unknowns)[which].signum();
    let (za, zb) = (
        unknown_vector(unknowns, p, &a.x),
        unknown_vector(unknowns, p, &b.x),
    );
    let chord = &zb - &za;
    let length = chord.norm();
    let direction = &chord / length;
    let size = za.amax().max(1.0);
    let (mut lo, mut hi) = ((0.0, a.clone()), (1.0, b.clone()));
    for _ in 0..60 {
        if (hi.0 - lo.0) * length <= LOCATE * size {
            break;
        }
        let s = 0.5 * (lo.0 + hi.0);
        let z = &za + &chord * s;
        let x = with_unknowns(unknowns, p, &a.x, &z);
        let trial = correct(section, unknowns, p, mode, x, Some((&z, &direction))).ok()?;
        if sign(&trial) == sign(&lo.1) {
            lo = (s, trial);
        } else {
            hi = (s, trial);
        }
    }
    let (lo, hi) = (lo.1, hi.1);
    Some(
        if tests(&lo.back, unknowns)[which].abs() <= tests(&hi.back, unknowns)[which].abs() {
            lo
        } else {
            hi
        },
    )
}

/// Follow the orbit at `x` (solved, just after a section event in `mode`)
/// as `plan` asks; `on_point` hears of each orbit as it joins the branch.
/// The branch ends, saying why, once the section is spent (interrupted,
/// or past its deadline).
pub fn follow(
    section: &Section,
    unknowns: &Unknowns,
    mode: Mode,
    x: Vec<f64>,
    plan: &Plan,
    on_point: &mut dyn FnMut(&Point),
) -> Branch {
    let p = plan.parameter;
    let k = unknowns.free.len();
    let mut points = Vec::new();
    let start = match correct(section, unknowns, p, mode, x, None) {
        Ok(s) => s,
        Err(why) => {
            return Branch {
                points,
                ended: format!("no orbit at the start: {why}"),
            };
        }
    };
    // A return that takes more than thrice the branch's period (the
    // latest orbit's) has missed the section (a trial orbit past a
    // graze): give up on it then, not at the scene's t_end.
    let whole = section;
    let capped = |period: f64| Section {
        t_max: whole.t_max.min(3.0 * period),
        ..*whole
    };
    let mut watched = grazing::impact_speed(section, mode, &start.x).map(|q| (start.x[p], q));
    // Every orbit's impact speed, and the orbit before `here`: where the
    // corrector cannot come near a graze, the speeds still locate it.
    let mut speeds: Vec<(f64, f64)> = watched.into_iter().collect();
    let mut before_here = None;
    let start_p = start.x[p];
    let range = (plan.to - start_p).abs().max(f64::MIN_POSITIVE);
    let (mut ds, ds_max) = (plan.step.0 * range, plan.step.1 * range);
    let toward = (plan.to - start.x[p]).signum();
    let mut previous = DVector::zeros(k + 1);
    previous[k] = toward;
    points.push(point(unknowns, p, &start, ""));
    let mut here = start;
    let mut ended = format!("stopped after {} orbits", plan.points);
    on_point(&points[0]);
    while points.len() < plan.points {
        let section = &capped(here.back.elapsed);
        if let Some(why) = section.spent() {
            ended = format!("{why}, after {} orbits", points.len());
            break;
        }
        let (_, a) = system(unknowns, p, &here.x, &here.back);
        let Some(t) = tangent(&a, &previous) else {
            ended = "the branch's tangent is undefined here".into();
            break;
        };
        let z0 = unknown_vector(unknowns, p, &here.x);
        // Past the end: the last orbit at the end's parameter itself.
        let z_pred = &z0 + &t * ds;
        if (z_pred[k] - plan.to) * toward >= 0.0 {
            let mut x = with_unknowns(unknowns, p, &here.x, &z_pred);
            x[p] = plan.to;
            match correct(section, unknowns, p, mode, x, None) {
                Ok(last) => {
                    push_with_bifurcations(section, unknowns, p, mode, &here, &last, &mut points);
                    ended = "reached".into();
                    break;
                }
                // Too far a leap to the end: come closer first.
                Err(why) => {
                    ds *= 0.5;
                    if ds < 1e-9 * range {
                        ended = format!("no orbit at the end: {why}");
                        break;
                    }
                    continue;
                }
            }
        }
        let x = with_unknowns(unknowns, p, &here.x, &z_pred);
        match correct(section, unknowns, p, mode, x, Some((&z_pred, &t))) {
            Ok(next) => {
                push_with_bifurcations(section, unknowns, p, mode, &here, &next, &mut points);
                if let Some(last) = points.last() {
                    on_point(last);
                }
                let speed = grazing::impact_speed(section, mode, &next.x).map(|q| (next.x[p], q));
                if let Some((at, orbit, state)) = watched
                    .zip(speed)
                    .and_then(|(before, now)| graze_ahead(before, now, (start_p, plan.to)))
                    .and_then(|guess| {
                        locate_grazing(section, unknowns, p, mode, (&here, &next), guess)
                    })
                {
                    let mut graze = point(unknowns, p, &orbit, "grazing");
                    graze.parameter = at;
                    graze.state = state;
                    unknowns.fold_clock(&mut graze.state);
                    on_point(&graze);
                    points.push(graze);
                    let side = if at > next.x[p] { "below" } else { "above" };
                    ended = format!(
                        "grazing at {at}: the impact speed falls to zero there, and the impacting \
                         orbits exist {side} it; the branch of impacting orbits ends"
                    );
                    break;
                }
                speeds.extend(speed);
                watched = speed;
                before_here = Some(std::mem::replace(&mut here, next));
                previous = t;
                ds = (ds * 1.3).min(ds_max);
            }
            Err(why) => {
                let grazed = why.contains("grazes") || why.contains("(a graze");
                ds *= 0.5;
                if !grazed && ds >= 1e-9 * range {
                    continue;
                }
                let why = if grazed {
                    format!("the corrector met a graze: {why}")
                } else {
                    format!("the step shrank to nothing: {why}")
                };
                let last = (before_here.as_ref(), &here);
                let range = (start_p, plan.to);
                ended = end_near_graze(unknowns, p, &speeds, last, range, &why, &mut points)
                    .unwrap_or(why);
                break;
            }
        }
    }
    if let Some(last) = points.last_mut()
        && last.label.is_empty()
    {
        last.label = "end".into();
    }
    Branch { points, ended }
}

/// How close a graze located from the impact speeds alone must be (its
/// two fits' distance, relative to the parameter's size) to be labelled.
const GRAZE_ACCURACY: f64 = 1e-9;

/// A branch whose corrector can go no further (`why`) where its orbits'
/// impact speeds (`speeds`) fall towards zero: the graze they locate,
/// labelled (its state on the secant through the last two orbits `last`)
/// where located to [`GRAZE_ACCURACY`], else how far short of it the
/// branch ends. `None` where the speeds put no graze ahead.
fn end_near_graze(
    unknowns: &Unknowns,
    p: usize,
    speeds: &[(f64, f64)],
    (before, here): (Option<&Solved>, &Solved),
    range: (f64, f64),
    why: &str,
    points: &mut Vec<Point>,
) -> Option<String> {
    let (at, accuracy) = grazing::extrapolated(speeds, range)?;
    let &(last, speed) = speeds.last()?;
    if accuracy > GRAZE_ACCURACY * at.abs().max(1.0) {
        return Some(format!(
            "the branch ends {:.2e} short of a graze its orbits' impact speeds put at {at} (to \
             {accuracy:.1e}; the last orbit, at {last}, impacts at speed {:.2e}), too far to \
             label: {why}",
            (at - last).abs(),
            speed.abs()
        ));
    }
    let mut graze = point(unknowns, p, here, "grazing");
    graze.parameter = at;
    if let Some(before) = before {
        let (a, b) = (&before.x, &here.x);
        let f = (at - b[p]) / (b[p] - a[p]);
        graze.state = a.iter().zip(b).map(|(a, b)| b + f * (b - a)).collect();
        graze.state[p] = at;
        unknowns.fold_clock(&mut graze.state);
    }
    points.push(graze);
    let side = if at > last { "below" } else { "above" };
    Some(format!(
        "grazing at {at} (to {accuracy:.0e}, where the impact speeds of the last three orbits \
         fall to zero; the corrector came within {:.2e} of it: {why}), and the impacting orbits \
         exist {side} it; the branch of impacting orbits ends",
        (at - last).abs()
    ))
}

/// Where the impact speed, falling from `before` to `now` (parameter,
/// speed), reaches zero, if it does within one and a half more such steps
/// and within the branch's `range` (see [`grazing::extrapolated`]).
fn graze_ahead(before: (f64, f64), now: (f64, f64), range: (f64, f64)) -> Option<f64> {
    let falling = now.1.signum() == before.1.signum() && now.1.abs() < before.1.abs();
    let zero = grazing::predicted(before, now)?;
    let step = now.0 - before.0;
    let ahead = (zero - now.0) / step;
    // A graze past `--to` is not met.
    (falling && grazing::within(zero, range) && (0.0..=1.5).contains(&ahead)).then_some(zero)
}

/// The grazing parameter near `guess`, approached from the impacting
/// orbits `previous` and `near` (see [`grazing`]): three orbits of its period corrected at
/// distances `3d`, `2d`, `d` short of the estimate (`d` a quarter of the
/// way from `near` at first), the zero of the quadratic
/// through their impact speeds the next estimate, `d` halved each round
/// (the fit's error falls eightfold), until the estimate moves by less
/// than 1e-12 of its size or the orbits are too near the graze to be
/// corrected. Also the orbit nearest the graze, and the grazing orbit's
/// section state (the secant through the last two carried to the
/// estimate).
fn locate_grazing(
    section: &Section,
    unknowns: &Unknowns,
    p: usize,
    mode: Mode,
    (previous, near): (&Solved, &Solved),
    guess: f64,
) -> Option<(f64, Solved, Vec<f64>)> {
    let toward = (guess - near.x[p]).signum();
    let (mut estimate, mut d) = (guess, 0.25 * (guess - near.x[p]).abs());
    let period = near.back.elapsed;
    // Each trial starts on the secant through the last two orbits (the
    // section state moves with the parameter: a start left behind would
    // miss the guard and return after another period).
    let mut last = (previous.clone(), near.clone());
    let mut rounds = 0;
    'rounds: for _ in 0..8 {
        let mut points = [(0.0, 0.0); 3];
        for (slot, k) in [3.0, 2.0, 1.0].into_iter().enumerate() {
            let target = estimate - toward * k * d;
            let (a, b) = (&last.0.x, &last.1.x);
            let f = (target - b[p]) / (b[p] - a[p]);
            let mut x: Vec<f64> = a.iter().zip(b).map(|(a, b)| b + f * (b - a)).collect();
            x[p] = target;
            // Too near the graze for the section map: the last estimate stands.
            // A forced orbit of another period (the corrector slid onto
            // another branch, closing on more forcing periods) is not this
            // branch's; an autonomous branch's period moves with it.
            let Some((orbit, q)) = correct(section, unknowns, p, mode, x, None)
                .ok()
                .filter(|o| {
                    unknowns.clock.is_none() || (o.back.elapsed - period).abs() <= 1e-6 * period
                })
                .and_then(|o| grazing::impact_speed(section, mode, &o.x).map(|q| (o, q)))
            else {
                break 'rounds;
            };
            points[slot] = (orbit.x[p], q);
            last = (last.1, orbit);
        }
        rounds += 1;
        let Some(next) = grazing::quadratic_zero(&points, estimate) else {
            break;
        };
        let moved = (next - estimate).abs();
        estimate = next;
        if moved <= 1e-12 * estimate.abs().max(1.0) {
            break;
        }
        d *= 0.5;
    }
    // The grazing orbit's section state: the last two orbits' secant
    // carried to the estimate.
    let (a, b) = (&last.0.x, &last.1.x);
    let f = (estimate - b[p]) / (b[p] - a[p]);
    let mut state: Vec<f64> = a.iter().zip(b).map(|(a, b)| b + f * (b - a)).collect();
    state[p] = estimate;
    (rounds > 0).then_some((estimate, last.1, state))
}

/// Push `next`, after the bifurcations between `here` and it.
fn push_with_bifurcations(
    section: &Section,
    unknowns: &Unknowns,
    p: usize,
    mode: Mode,
    here: &Solved,
    next: &Solved,
    points: &mut Vec<Point>,
) {
    let (before, after) = (tests(&here.back, unknowns), tests(&next.back, unknowns));
    for which in 0..3 {
        // A test function that stays within round-off of zero (a
        // conservative orbit's multiplier 1, always) marks nothing.
        let clear = |v: f64| v.abs() > 1e-9;
        // A pair of multipliers turning real is no torus.
        let same_pairs = which != 2 || before[3] == after[3];
        if same_pairs
            && clear(before[which])
            && clear(after[which])
            && before[which].signum() != after[which].signum()
            && let Some(at) = locate(section, unknowns, p, mode, (here, next), which)
        {
            points.push(point(unknowns, p, &at, LABELS[which]));
        }
    }
    points.push(point(unknowns, p, next, ""));
}
