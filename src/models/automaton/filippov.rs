//! Discontinuous flows as Filippov defined them: a mode whose flow reads
//! `sign(h)` becomes the regions between its switching surfaces, each with
//! a smooth flow, and a sliding mode on each surface; what the engine then
//! runs is a plain automaton.
//!
//! - **Surfaces.** Each distinct argument `h` of a `sign()` in a mode's flow
//!   (at most [`MAX_SURFACES`]) is a switching surface. A region fixes
//!   every `sign(h)` to `+1` or `-1`; its mode is named after the signs
//!   (`slip[v>0]`), and its flow is compiled like any other (an affine
//!   region keeps the exact propagator, another Taylor's method).
//! - **Crossing.** Each region has a marker on each surface, crossed from
//!   its side (`cross:v`). Where it fires, the other side's flow decides:
//!   if it carries the state on, the run enters the other region; if it
//!   points back too (both sides point into the surface), the run slides
//!   (`slide:v`).
//! - **Sliding** follows Filippov's convex combination `f_s = f- + a (f+ -
//!   f-)`, `a = L- / (L- - L+)`, with `L+-` the rate of `h` along each side's
//!   flow: tangent to the surface. Where the surface is one state (or a
//!   state less a constant), that state's rate is exactly zero, so the run
//!   never drifts off it. Sliding ends where one side's flow turns tangent
//!   and then away (`L-` falling through zero, or `L+` rising through it):
//!   `leave:v`, into that side.
//! - **Two surfaces at once** (a second reached while sliding on one, or
//!   a start on both): where the four regions' flows around all cross one
//!   of them the same way (a block that reverses while another sticks),
//!   the state passes through it and the other decides as above.
//! - **What has no answer.** A surface both sides flow away from
//!   (repelling: the solution is not unique) and two surfaces at once that
//!   neither is passed through (sliding on both: codimension two) stop the
//!   run with the reason: each is a mode of its own that says so
//!   ([`Expanded::stops`]).
//!
//! A mode's own transitions apply in each of its regions and sliding
//! modes; one that leads into a mode with surfaces enters the region the
//! state lies in after its reset (or slides, or stops, by the rules above
//! applied on the spot). So does the start.

use crate::engine::Direction;
use crate::expr::Ast;
use crate::expr::symbolic::{
    add, constant, derivative, div, fix_signs, mul, same, sign_arguments, sub, text,
};
use crate::models::automaton::definition::{Definition, ModeDef, Rest, Source, Transition};
use crate::scene::SceneError;

/// The most switching surfaces one mode's flow may read (`2^4` regions).
pub const MAX_SURFACES: usize = 4;

/// The automaton with every mode that reads `sign()` expanded.
#[derive(Debug, Clone)]
pub struct Expanded {
    /// The plain automaton: each mode without `sign()` as it was, each with
    /// it replaced by its regions, sliding modes and refusals.
    pub definition: Definition,
    /// How each transition of each mode of `definition` picks its mode.
    pub targets: Vec<Vec<Target>>,
    /// The modes that were expanded.
    pub families: Vec<Family>,
    /// For each mode of `definition`, the reason it stops a run with, where
    /// it is a refusal.
    pub stops: Vec<Option<String>>,
    /// The mode `definition.initial_mode` names, as a target: where the
    /// file's initial mode has surfaces, the start is decided on the spot.
    pub start: Target,
    /// For each mode of the file, the modes of `definition` it became (its
    /// regions and sliding modes, for one with surfaces).
    pub origins: Vec<Vec<usize>>,
}

/// How a transition picks the mode after it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// The transition's `to`.
    Fixed,
    /// The region of family `.0` the state lies in after the reset.
    Enter(usize),
    /// Surface `surface` of family `family`, reached from the positive side
    /// (or not): the other side's region, or sliding.
    Across {
        /// The family.
        family: usize,
        /// Its surface.
        surface: usize,
    },
    /// The transition's `to`, a region the state enters leaving a sliding
    /// on the surface of that region's guard `.0`, along the flow.
    Leave(usize),
    /// Surface `surface` of family `family` reached while sliding on its
    /// surface `sliding`: on both at once, where the flows around decide.
    AcrossSliding {
        /// The family.
        family: usize,
        /// The surface reached.
        surface: usize,
        /// The surface slid on.
        sliding: usize,
    },
}

/// A file's mode with switching surfaces, expanded.
#[derive(Debug, Clone)]
pub struct Family {
    /// The file's name of the mode.
    pub name: String,
    /// Each surface `h`.
    pub surfaces: Vec<Source>,
    /// The mode of each region: bit `j` of the index set where `h_j < 0`.
    pub regions: Vec<usize>,
    /// The rate of each surface along each region's flow: `rates[region][j]`.
    pub rates: Vec<Vec<Source>>,
    /// The sliding mode on surface `j` with the other surfaces' signs as in
    /// `region` (its bit `j` ignored): `sliding[j][region]`.
    pub sliding: Vec<Vec<usize>>,
    /// The refusal for a repelling surface, and for two surfaces at once.
    pub repelling: Vec<usize>,
    /// The state each surface is, up to a constant, if it is one (see
    /// `held_state`): a slide puts it exactly on the surface.
    pub held: Vec<Option<usize>>,
    /// The same for reaching a second surface while sliding.
    pub double: usize,
}

/// The event names the expansion gives: `cross:h`, `slide:h`, `leave:h`.
pub fn event_name(kind: &str, surface: &Source) -> String {
    format!("{kind}:{}", surface.text)
}

/// Expand every mode of `definition` whose flow reads `sign()`; a `sign()`
/// elsewhere than in a flow, nested in another's argument, or more than
/// [`MAX_SURFACES`] surfaces in one mode, is refused with its field.
pub fn expand(definition: &Definition) -> Result<Expanded, SceneError> {
    check_placement(definition)?;
    let surfaces: Vec<Vec<(Ast, usize)>> = definition
        .modes
        .iter()
        .map(|m| {
            let mut found = Vec::new();
            for source in m.flow.iter().flatten() {
                sign_arguments(&source.ast, &mut found);
            }
            found
        })
        .collect();
    // New index of each file mode (its first region, for an expanded one).
    let mut first = Vec::new();
    let mut count = 0;
    for found in &surfaces {
        first.push(count);
        count += match found.len() {
            0 => 1,
            k => (1 << k) + k * (1 << (k - 1)) + k + 1,
        };
    }
    let varies = |name: &str| definition.states.iter().any(|s| s == name) || name == "t";
    let variables: Vec<&str> = (definition.states.iter().map(String::as_str))
        .chain(["t"])
        .collect();
    let mut modes = Vec::new();
    let mut targets = Vec::new();
    let mut stops = Vec::new();
    let mut families = Vec::new();
    let mut energy = definition.energy.as_ref().map(|_| Vec::new());
    let mut origins = Vec::new();
    // The file's transitions of a mode, as they go into any of its
    // expansions: a target with surfaces is entered by region.
    let own = |m: &ModeDef| -> (Vec<Transition>, Vec<Target>) {
        let mut family = 0;
        let family_of: Vec<Option<usize>> = surfaces
            .iter()
            .map(|s| {
                (!s.is_empty()).then(|| {
                    family += 1;
                    family - 1
                })
            })
            .collect();
        m.transitions
            .iter()
            .map(|t| {
                let mut t = t.clone();
                let target = match family_of[t.to] {
                    Some(f) => Target::Enter(f),
                    None => Target::Fixed,
                };
                t.to = first[t.to];
                (t, target)
            })
            .unzip()
    };
    for (index, (mode, found)) in definition.modes.iter().zip(&surfaces).enumerate() {
        let energy_of = definition.energy.as_ref().map(|e| e[index].clone());
        let (transitions, transition_targets) = own(mode);
        if found.is_empty() {
            // A resting mode is one of the file's: entered as it is.
            let rest = match &mode.rest {
                Some(rest) if !surfaces[rest.to].is_empty() => {
                    return Err(SceneError::field(
                        &format!("modes.{}.rest.to", mode.name),
                        format!(
                            "mode `{}` switches its flow by sign(): a resting mode must not",
                            definition.modes[rest.to].name
                        ),
                    ));
                }
                Some(rest) => Some(Rest {
                    to: first[rest.to],
                    reset: rest.reset.clone(),
                }),
                None => None,
            };
            modes.push(ModeDef {
                transitions,
                rest,
                ..mode.clone()
            });
            targets.push(transition_targets);
            stops.push(None);
            origins.push(vec![first[index]]);
            if let (Some(all), Some(e)) = (energy.as_mut(), energy_of) {
                all.push(e);
            }
            continue;
        }
        if mode.rest.is_some() {
            return Err(SceneError::field(
                &format!("modes.{}.rest", mode.name),
                "a mode whose flow switches by sign() slides rather than piles up impacts: \
                 it takes no rest"
                    .into(),
            ));
        }
        // The flow the surfaces were read from: errors point into it.
        let Some(source) = mode.flow.iter().flatten().next() else {
            return Err(SceneError::field(
                &format!("modes.{}.flow", mode.name),
                "reads sign() but has no rate to read it from".into(),
            ));
        };
        let family = families.len();
        let k = found.len();
        if k > MAX_SURFACES {
            return Err(source.error(
                found[MAX_SURFACES].1,
                &format!(
                    "mode `{}` switches on {k} surfaces (`sign` of {k} expressions); at most \
                     {MAX_SURFACES} are taken",
                    mode.name
                ),
            ));
        }
        let base = first[index];
        let path = |suffix: &str| format!("modes.{}.flow (the {suffix})", mode.name);
        let surface_sources: Vec<Source> = found
            .iter()
            .map(|(h, _)| Source {
                text: text(h),
                path: path("switching surface"),
                ast: h.clone(),
            })
            .collect();
        // A region's signs: bit j set where h_j < 0.
        let sign_of = |region: usize, j: usize| if region >> j & 1 == 1 { -1.0 } else { 1.0 };
        let name_of = |region: usize, sliding: Option<usize>| {
            let parts: Vec<String> = (0..k)
                .map(|j| {
                    let relation = match sliding {
                        Some(s) if s == j => "=",
                        _ if sign_of(region, j) > 0.0 => ">",
                        _ => "<",
                    };
                    format!("{}{relation}0", surface_sources[j].text)
                })
                .collect();
            format!("{}[{}]", mode.name, parts.join(", "))
        };
        let flow_of = |region: usize| -> Vec<Ast> {
            mode.flow
                .iter()
                .map(|rate| match rate {
                    None => Ast::Number(0.0),
                    Some(source) => fix_signs(&source.ast, &|h| {
                        found
                            .iter()
                            .position(|(f, _)| same(f, h))
                            .map(|j| sign_of(region, j))
                    }),
                })
                .collect()
        };
        // The rate of surface j along the flow `flow`: dh/dx . flow (+ dh/dt).
        let lie = |j: usize, flow: &[Ast]| -> Result<Ast, SceneError> {
            let (h, at) = &found[j];
            let fail = |why: String| source.error(*at, &why);
            let mut rate = derivative(h, "t", &varies).map_err(fail)?;
            for (state, f) in definition.states.iter().zip(flow) {
                let d = derivative(h, state, &varies).map_err(fail)?;
                rate = add(rate, mul(d, f.clone()));
            }
            Ok(rate)
        };
        let source = |ast: Ast, suffix: &str| Source {
            text: text(&ast),
            path: path(suffix),
            ast,
        };
        let regions: Vec<usize> = (0..1 << k).map(|r| base + r).collect();
        let sliding_base = base + (1 << k);
        let sliding: Vec<Vec<usize>> = (0..k)
            .map(|j| {
                (0..1 << k)
                    .map(|r| {
                        // The other surfaces' bits, with bit j squeezed out.
                        let low = r & ((1 << j) - 1);
                        let high = (r >> (j + 1)) << j;
                        sliding_base + j * (1 << (k - 1)) + (low | high)
                    })
                    .collect()
            })
            .collect();
        let refusals = sliding_base + k * (1 << (k - 1));
        origins.push((base..refusals).collect());
        let repelling: Vec<usize> = (0..k).map(|j| refusals + j).collect();
        let double = refusals + k;
        let mut rates = Vec::new();
        for region in 0..1 << k {
            let flow = flow_of(region);
            rates.push(
                (0..k)
                    .map(|j| Ok(source(lie(j, &flow)?, "surface's rate")))
                    .collect::<Result<Vec<_>, SceneError>>()?,
            );
        }
        // The regions.
        for region in 0..1 << k {
            let flow = flow_of(region);
            let mut region_transitions = transitions.clone();
            let mut region_targets = transition_targets.clone();
            for (j, surface) in surface_sources.iter().enumerate() {
                region_transitions.push(Transition {
                    name: event_name("cross", surface),
                    guard: surface.clone(),
                    direction: if sign_of(region, j) > 0.0 {
                        Direction::Falling
                    } else {
                        Direction::Rising
                    },
                    reset: Vec::new(),
                    to: regions[region ^ (1 << j)],
                    priority: 0.0,
                    terminal: false,
                    barrier: false,
                });
                region_targets.push(Target::Across { family, surface: j });
            }
            modes.push(ModeDef {
                name: name_of(region, None),
                flow: flow
                    .into_iter()
                    .map(|a| Some(source(a, "region's flow")))
                    .collect(),
                transitions: region_transitions,
                rest: None,
            });
            targets.push(region_targets);
            stops.push(None);
        }
        // The sliding modes: on surface j, the others' signs as `rest`.
        for j in 0..k {
            for rest in 0..1 << (k - 1) {
                // The region index with bit j clear (+) and set (-).
                let low = rest & ((1 << j) - 1);
                let high = (rest >> j) << (j + 1);
                let plus = low | high;
                let minus = plus | (1 << j);
                let (f_plus, f_minus) = (flow_of(plus), flow_of(minus));
                let (l_plus, l_minus) = (&rates[plus][j].ast, &rates[minus][j].ast);
                // a = L- / (L- - L+), f_s = f- + a (f+ - f-).
                // Where the sides' flows differ by a constant (a relay), the
                // quotient is by a constant and the jump it scales is one:
                // an affine region's sliding flow stays affine, for the
                // exact propagator.
                let gap = sub(l_minus.clone(), l_plus.clone());
                let gap = constant(&gap, &variables).unwrap_or(gap);
                let a = div(l_minus.clone(), gap);
                let held = held_state(&found[j].0, &definition.states, &varies);
                let flow: Vec<Option<Source>> = f_plus
                    .iter()
                    .zip(&f_minus)
                    .enumerate()
                    .map(|(i, (p, m))| {
                        let rate = if Some(i) == held {
                            Ast::Number(0.0)
                        } else {
                            let jump = sub(p.clone(), m.clone());
                            let jump = constant(&jump, &variables).unwrap_or(jump);
                            add(m.clone(), mul(a.clone(), jump))
                        };
                        Some(source(rate, "sliding flow"))
                    })
                    .collect();
                let mut sliding_transitions = transitions.clone();
                let mut sliding_targets = transition_targets.clone();
                let surface = &surface_sources[j];
                // The region's own transitions come first, then one marker
                // per surface: surface j's is this one.
                let crossing = transitions.len() + j;
                for (guard, direction, to) in [
                    (&rates[minus][j], Direction::Falling, regions[minus]),
                    (&rates[plus][j], Direction::Rising, regions[plus]),
                ] {
                    sliding_transitions.push(Transition {
                        name: event_name("leave", surface),
                        guard: guard.clone(),
                        direction,
                        reset: Vec::new(),
                        to,
                        priority: 0.0,
                        terminal: false,
                        barrier: false,
                    });
                    sliding_targets.push(Target::Leave(crossing));
                }
                for (o, surface) in surface_sources.iter().enumerate().filter(|(o, _)| *o != j) {
                    sliding_transitions.push(Transition {
                        name: event_name("cross", surface),
                        guard: surface.clone(),
                        direction: Direction::Either,
                        reset: Vec::new(),
                        to: double,
                        priority: 0.0,
                        terminal: false,
                        barrier: false,
                    });
                    sliding_targets.push(Target::AcrossSliding {
                        family,
                        surface: o,
                        sliding: j,
                    });
                }
                modes.push(ModeDef {
                    name: name_of(plus, Some(j)),
                    flow,
                    transitions: sliding_transitions,
                    rest: None,
                });
                targets.push(sliding_targets);
                stops.push(None);
            }
        }
        // The refusals: frozen, no transitions.
        for surface in &surface_sources {
            modes.push(ModeDef {
                name: format!("{}[{}: repelling]", mode.name, surface.text),
                flow: vec![None; definition.states.len()],
                transitions: Vec::new(),
                rest: None,
            });
            targets.push(Vec::new());
            stops.push(Some(format!(
                "the state sits on the switching surface `{}` = 0 of mode `{}`, and the flows on \
                 both sides point away from it: the solution is not unique there (Filippov), so \
                 the run cannot go on",
                surface.text, mode.name
            )));
        }
        modes.push(ModeDef {
            name: format!("{}[two surfaces]", mode.name),
            flow: vec![None; definition.states.len()],
            transitions: Vec::new(),
            rest: None,
        });
        targets.push(Vec::new());
        stops.push(Some(format!(
            "the state reaches a second switching surface of mode `{}` while it sits on one, and \
             the flows around carry it through neither: sliding on two surfaces at once \
             (codimension two) is not taken",
            mode.name
        )));
        if let (Some(all), Some(e)) = (energy.as_mut(), energy_of) {
            all.extend(std::iter::repeat_n(e, modes.len() - all.len()));
        }
        families.push(Family {
            name: mode.name.clone(),
            held: found
                .iter()
                .map(|(h, _)| held_state(h, &definition.states, &varies))
                .collect(),
            surfaces: surface_sources,
            regions,
            rates,
            sliding,
            repelling,
            double,
        });
    }
    let start = if surfaces[definition.initial_mode].is_empty() {
        Target::Fixed
    } else {
        Target::Enter(
            surfaces[..definition.initial_mode]
                .iter()
                .filter(|s| !s.is_empty())
                .count(),
        )
    };
    Ok(Expanded {
        definition: Definition {
            modes,
            initial_mode: first[definition.initial_mode],
            energy,
            ..definition.clone()
        },
        targets,
        families,
        stops,
        start,
        origins,
    })
}

/// The state a surface is, up to a constant (`v`, `x - 1`): its gradient a
/// constant unit vector on that state. Its rate in the sliding flow is then
/// exactly zero.
fn held_state(h: &Ast, states: &[String], varies: &dyn Fn(&str) -> bool) -> Option<usize> {
    if derivative(h, "t", varies).ok()? != Ast::Number(0.0) {
        return None;
    }
    let mut held = None;
    for (i, state) in states.iter().enumerate() {
        match derivative(h, state, varies).ok()? {
            Ast::Number(z) if z == 0.0 => {}
            Ast::Number(one) if one == 1.0 && held.is_none() => held = Some(i),
            _ => return None,
        }
    }
    held
}

/// `sign()` belongs in flows, with one argument, not nested: refused
/// elsewhere with its field and character.
fn check_placement(definition: &Definition) -> Result<(), SceneError> {
    fn calls(ast: &Ast, inside: bool, out: &mut Vec<(usize, &'static str)>) {
        match ast {
            Ast::Number(_) | Ast::Name(..) => {}
            Ast::Neg(a) => calls(a, inside, out),
            Ast::Binary(_, a, b) => {
                calls(a, inside, out);
                calls(b, inside, out);
            }
            Ast::Call(name, args, at) => {
                if name == "sign" {
                    if args.len() != 1 {
                        out.push((*at, "`sign` takes 1 argument"));
                    } else if inside {
                        out.push((
                            *at,
                            "`sign` inside the argument of another `sign` is not a surface",
                        ));
                    }
                    args.iter().for_each(|a| calls(a, true, out));
                } else {
                    args.iter().for_each(|a| calls(a, inside, out));
                }
            }
        }
    }
    let variables: Vec<&str> = (definition.states.iter().map(String::as_str))
        .chain(["t"])
        .collect();
    let flows: Vec<&Source> = definition
        .modes
        .iter()
        .flat_map(|m| m.flow.iter().flatten())
        .collect();
    for source in definition.sources() {
        let mut found = Vec::new();
        calls(&source.ast, false, &mut found);
        let in_flow = flows.iter().any(|f| std::ptr::eq(*f, source));
        if let Some((at, why)) = found.first() {
            return Err(source.error(*at, why));
        }
        let mut signs = Vec::new();
        sign_arguments(&source.ast, &mut signs);
        if let (false, Some((_, at))) = (in_flow, signs.first()) {
            return Err(source.error(
                *at,
                "`sign` switches a flow between the regions of its surface; in a guard, a reset \
                 or an energy write what it means with transitions instead",
            ));
        }
        // As a guard that never crosses zero is refused.
        if let Some((h, at)) = signs
            .iter()
            .find(|(h, _)| constant(h, &variables).is_some())
        {
            return Err(source.error(
                *at,
                &format!(
                    "`sign({})` changes with neither the state nor the time, so it switches \
                     nothing: write its value instead (a parameter holding the sign)",
                    text(h)
                ),
            ));
        }
    }
    Ok(())
}
