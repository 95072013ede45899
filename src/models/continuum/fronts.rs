//! The string by front tracking: the exact solution for piecewise-constant
//! data, as an event-local model on the generic engine.
//!
//! Between events the string is a row of constant [`Piece`]s separated by
//! fronts moving at `+-c`. Events are the fronts' meetings: two fronts
//! crossing (the jump between the pieces on either side splits anew,
//! [`Continuum::between`]), a front reaching the wall or the loaded end
//! (it reflects, keeping the invariant it carries in), and an impact. Each
//! is exact: the pieces are exact solutions, the event times are exact up
//! to rounding of a position, and a crossing touches two fronts, so an
//! event costs the same however many fronts there are. Nothing smooths a
//! jump, so nothing oscillates at one.
//!
//! The constraint. A crossing or a reflection that would leave a piece
//! below `eps = 0` is compression the string has to resist. The paper's
//! continuum says one thing there, (A.12): at an impact the kinetic energy
//! is kept and the velocity flips. That is a rule for a shut stretch (at
//! `eps = 0`, rigid under compression) striking the wall: the whole stretch
//! bounces as one body, `v -> -v`, which keeps energy and is what happens
//! when the release's front reaches the wall. Elsewhere (an open piece
//! pressed against the wall, two stretches meeting in compression) the
//! paper's continuum has no continuation that keeps energy, and the run
//! stops there and says so rather than invent one.
//!
//! Guards: [`WALL`], [`IMPACT`], one crossing slot per neighbouring pair of
//! fronts, and the end; a reset re-predicts only its neighbours' slots.

use std::ops::Range;

use crate::engine::{Direction, Fired, Guard, Label, Labels, LocalModel};
use crate::models::chain::coarse::{Coarse, WINDOW_WIDTH};
use crate::models::continuum::{Continuum, Piece, StringModel};
use crate::time::Time;

/// Guard slot of a front reaching the wall.
pub const WALL: usize = 0;
/// Guard slot of a shut stretch striking the wall.
pub const IMPACT: usize = 1;
/// Guard slot of the crossing of fronts 0 and 1; fronts `i` and `i + 1`
/// have slot `FIRST_CROSSING + i`, and the end the last slot.
const FIRST_CROSSING: usize = 2;

/// Fronts impacts may add beyond those the run starts with (each adds at
/// most two: one leaving the wall, one more where the bounced stretch's
/// far edge splits), so room for 32 impacts; a run that needs more stops
/// and says so.
const RESERVE: usize = 64;

#[derive(Debug, Clone, Copy, PartialEq)]
struct Front {
    /// Position at time `t0`.
    x0: f64,
    t0: f64,
    /// Moving towards the loaded end (`+c`) or the wall (`-c`).
    rightward: bool,
}

impl Front {
    fn at(self, t: f64, c: f64) -> f64 {
        let speed = if self.rightward { c } else { -c };
        self.x0 + speed * (t - self.t0)
    }
}

/// The string's exact motion from piecewise-constant data.
#[derive(Debug, Clone)]
pub struct FrontTracking {
    string: Continuum,
    /// Sorted by position; `pieces[i]` lies left of `fronts[i]`.
    fronts: Vec<Front>,
    pieces: Vec<Piece>,
    guards: Vec<Guard>,
    /// Largest number of fronts (one crossing slot per neighbouring pair).
    capacity: usize,
    /// Strains this close to zero are shut (round-off of the invariants).
    shut_below: f64,
    /// A shut stretch touches the wall moving into it.
    impact_due: bool,
    /// Momentum the wall has given up to `wall_since` (its pull and the
    /// impacts), and the momentum at `t = 0`.
    wall_given: f64,
    wall_since: f64,
    momentum_initial: f64,
}

impl FrontTracking {
    /// The string released at `t = 0` from `cells`, equal cells from the
    /// wall to the loaded end with a constant state each; the jumps between
    /// them and the boundary conditions split into fronts at once.
    pub fn new(string: Continuum, cells: &[Piece]) -> Result<Self, String> {
        let Some(&first) = cells.first() else {
            return Err("the string needs at least one cell".into());
        };
        let c = string.wave_speed;
        if !(string.length.is_finite() && string.length > 0.0 && c.is_finite() && c > 0.0) {
            return Err("length and wave speed must be positive and finite".into());
        }
        if !string.load.is_finite()
            || cells
                .iter()
                .any(|p| !(p.strain.is_finite() && p.velocity.is_finite()))
        {
            return Err("every strain, velocity and the load must be finite".into());
        }
        let scale = cells
            .iter()
            .map(|p| p.strain.abs().max(p.velocity.abs() / c))
            .fold(string.end_strain().abs(), f64::max)
            .max(f64::MIN_POSITIVE);
        let mut model = FrontTracking {
            capacity: 0,
            fronts: Vec::new(),
            pieces: vec![first],
            guards: Vec::new(),
            shut_below: 64.0 * f64::EPSILON * scale,
            impact_due: false,
            wall_given: 0.0,
            wall_since: 0.0,
            momentum_initial: 0.0,
            string,
        };
        let cell = model.string.length / cells.len() as f64;
        for (j, pair) in cells.windows(2).enumerate() {
            let x = model.string.wall() + (j + 1) as f64 * cell;
            let (fronts, pieces) = model.split(x, 0.0, pair[0], pair[1])?;
            model.fronts.extend(fronts);
            model.pieces.extend(pieces);
        }
        let last = *model.pieces.last().expect("one piece at least");
        let at_end = model.snap(model.string.reflected_at_end(last));
        if at_end != last {
            model.fronts.push(Front {
                x0: model.string.end(),
                t0: 0.0,
                rightward: false,
            });
            model.pieces.push(at_end);
        }
        model.reflect_at_wall(0.0)?;
        model.capacity = model.fronts.len() + RESERVE;
        let mut guards = vec![
            Guard::affine("wall", Direction::Falling),
            Guard::affine("impact", Direction::Falling),
        ];
        guards.extend(std::iter::repeat_n(
            Guard::affine("crossing", Direction::Falling),
            model.capacity - 1,
        ));
        guards.push(Guard::affine("end", Direction::Falling));
        model.guards = guards;
        model.momentum_initial = model.momentum(Time::new(0.0));
        Ok(model)
    }

    /// The string's parameters.
    pub fn string(&self) -> &Continuum {
        &self.string
    }

    /// The edges of the pieces at `t`: the wall, every front, the end.
    fn edges(&self, t: f64) -> impl Iterator<Item = f64> + '_ {
        let c = self.string.wave_speed;
        std::iter::once(self.string.wall())
            .chain(self.fronts.iter().map(move |f| f.at(t, c)))
            .chain(std::iter::once(self.string.end()))
    }

    /// Each piece with its extent `[a, b]` at `t`.
    fn extents(&self, t: f64) -> impl Iterator<Item = (Piece, f64, f64)> + '_ {
        self.pieces
            .iter()
            .zip(self.edges(t).zip(self.edges(t).skip(1)))
            .map(|(&p, (a, b))| (p, a, b))
    }

    fn wall_given_until(&self, t: f64) -> f64 {
        self.wall_given - self.string.force(self.pieces[0]) * (t - self.wall_since)
    }

    /// Clamp a strain within round-off of zero to zero (under the
    /// constraint), so a shut piece is exactly shut.
    fn snap(&self, mut p: Piece) -> Piece {
        if self.string.constraint && p.strain.abs() <= self.shut_below {
            p.strain = 0.0;
        }
        p
    }

    fn compressed(&self, p: Piece) -> bool {
        self.string.constraint && p.strain < 0.0
    }

    /// The fronts and the pieces right of them that the jump from `l` to
    /// `r` at `x` splits into at `t` (none of zero strength).
    fn split(
        &self,
        x: f64,
        t: f64,
        l: Piece,
        r: Piece,
    ) -> Result<(Vec<Front>, Vec<Piece>), String> {
        let (mut fronts, mut pieces) = (Vec::new(), Vec::new());
        if l == r {
            return Ok((fronts, pieces));
        }
        let m = self.snap(self.string.between(l, r));
        if self.compressed(m) {
            return Err(no_continuation(x, t, m));
        }
        for (rightward, piece) in [(false, m), (true, r)] {
            let behind = pieces.last().copied().unwrap_or(l);
            if piece != behind {
                fronts.push(Front {
                    x0: x,
                    t0: t,
                    rightward,
                });
                pieces.push(piece);
            }
        }
        Ok((fronts, pieces))
    }

    /// Settle the wall's account up to `t` before the piece at the wall
    /// changes.
    fn wall_changes(&mut self, t: f64) {
        self.wall_given = self.wall_given_until(t);
        self.wall_since = t;
    }

    /// Make the piece at the wall satisfy `v = 0` from `t`: a right-moving
    /// front leaves the wall, or (a shut stretch moving into it) an impact
    /// falls due.
    fn reflect_at_wall(&mut self, t: f64) -> Result<(), String> {
        let at_wall = self.pieces[0];
        let reflected = self.snap(self.string.reflected_at_wall(at_wall));
        if reflected == at_wall {
            return Ok(());
        }
        if self.compressed(reflected) {
            if at_wall.strain == 0.0 {
                self.impact_due = true;
                return Ok(());
            }
            return Err(no_continuation(self.string.wall(), t, reflected));
        }
        self.wall_changes(t);
        self.fronts.insert(
            0,
            Front {
                x0: self.string.wall(),
                t0: t,
                rightward: true,
            },
        );
        self.pieces.insert(0, reflected);
        Ok(())
    }

    fn end_slot(&self) -> usize {
        self.guards.len() - 1
    }

    fn all(&self) -> Range<usize> {
        0..self.guards.len()
    }

    /// A front reaches the wall.
    fn at_wall(&mut self, t: f64) -> Result<Fired, String> {
        self.wall_changes(t);
        let count = self.fronts.len();
        self.fronts.remove(0);
        self.pieces.remove(0);
        self.reflect_at_wall(t)?;
        // A plain reflection keeps every front's slot: only the wall's
        // neighbours change (and the end's, with one front).
        let affects = if self.fronts.len() == count && count >= 2 {
            WALL..FIRST_CROSSING + 1
        } else {
            self.all()
        };
        Ok(self.fired(affects, self.string.wall(), None))
    }

    /// A shut stretch strikes the wall and bounces as one body.
    fn impact(&mut self, t: f64) -> Result<Fired, String> {
        self.impact_due = false;
        let c = self.string.wave_speed;
        let stretch = self.pieces[0];
        let reach = self
            .fronts
            .first()
            .map_or(self.string.end(), |f| f.at(t, c));
        let mass = reach - self.string.wall();
        let speed = -stretch.velocity;
        let bounced = Piece {
            strain: 0.0,
            velocity: speed,
        };
        self.wall_changes(t);
        self.wall_given += 2.0 * mass * speed;
        self.pieces[0] = bounced;
        // The stretch's other edge no longer matches its neighbour: the
        // jump there splits anew.
        if self.fronts.is_empty() {
            let at_end = self.snap(self.string.reflected_at_end(bounced));
            if at_end != bounced {
                self.fronts.push(Front {
                    x0: self.string.end(),
                    t0: t,
                    rightward: false,
                });
                self.pieces.push(at_end);
            }
        } else {
            let (fronts, pieces) = self.split(reach, t, bounced, self.pieces[1])?;
            self.fronts.splice(0..1, fronts);
            self.pieces.splice(1..2, pieces);
        }
        self.reflect_at_wall(t)?;
        if self.fronts.len() > self.capacity {
            return Err(format!(
                "more than {} fronts after an impact; the front-tracking run has no room for more",
                self.capacity
            ));
        }
        Ok(self.fired(self.all(), self.string.wall(), Some(speed)))
    }

    /// The last front reaches the loaded end and reflects.
    fn at_end(&mut self, t: f64) -> Fired {
        let k = self.fronts.len();
        let arriving = self.pieces[k - 1];
        self.pieces[k] = self.snap(self.string.reflected_at_end(arriving));
        self.fronts[k - 1] = Front {
            x0: self.string.end(),
            t0: t,
            rightward: false,
        };
        let from = if k >= 2 { FIRST_CROSSING + k - 2 } else { 0 };
        self.fired(from..self.guards.len(), self.string.end(), None)
    }

    /// Fronts `i` and `i + 1` meet.
    fn crossing(&mut self, i: usize, t: f64) -> Result<Fired, String> {
        let c = self.string.wave_speed;
        let x = 0.5 * (self.fronts[i].at(t, c) + self.fronts[i + 1].at(t, c));
        let m = self.snap(self.string.between(self.pieces[i], self.pieces[i + 2]));
        if self.compressed(m) {
            return Err(no_continuation(x, t, m));
        }
        self.pieces[i + 1] = m;
        self.fronts[i] = Front {
            x0: x,
            t0: t,
            rightward: false,
        };
        self.fronts[i + 1] = Front {
            x0: x,
            t0: t,
            rightward: true,
        };
        let lo = if i == 0 { 0 } else { FIRST_CROSSING + i - 1 };
        let hi = if i + 2 == self.fronts.len() {
            self.guards.len()
        } else {
            FIRST_CROSSING + i + 2
        };
        Ok(self.fired(lo..hi, x, None))
    }

    fn fired(&self, affects: Range<usize>, x: f64, rel_velocity: Option<f64>) -> Fired {
        Fired {
            affects,
            labels: Labels::NONE
                .with_some("rel_velocity", rel_velocity.map(Label::Number))
                .with("x", Label::Number(x)),
        }
    }
}

/// Why the paper's continuum stops: compression it cannot carry.
fn no_continuation(x: f64, t: f64, m: Piece) -> String {
    format!(
        "compression at x = {x:.9}, t = {t}: the string would be left at strain {:e} < 0; the paper's continuum keeps energy across an impact (A.12) only for a shut stretch striking the wall as one body, and has no continuation here",
        m.strain
    )
}

impl LocalModel for FrontTracking {
    fn mode_name(&self) -> &'static str {
        "string"
    }

    fn guards(&self) -> &[Guard] {
        &self.guards
    }

    fn predict(&self, guard: usize, now: Time) -> Result<Option<Time>, String> {
        let (t, c) = (now.value(), self.string.wave_speed);
        let k = self.fronts.len();
        let delay = match guard {
            WALL => self
                .fronts
                .first()
                .filter(|f| !f.rightward)
                .map(|f| (f.at(t, c) - self.string.wall()) / c),
            IMPACT => self.impact_due.then_some(0.0),
            g if g == self.end_slot() => self
                .fronts
                .last()
                .filter(|f| f.rightward)
                .map(|f| (self.string.end() - f.at(t, c)) / c),
            g => {
                let i = g - FIRST_CROSSING;
                (i + 1 < k && self.fronts[i].rightward && !self.fronts[i + 1].rightward)
                    .then(|| (self.fronts[i + 1].at(t, c) - self.fronts[i].at(t, c)) / (2.0 * c))
            }
        };
        Ok(delay.map(|d| now.after(d.max(0.0))))
    }

    fn fire(&mut self, guard: usize, t: Time) -> Result<Fired, String> {
        let t = t.value();
        match guard {
            WALL => self.at_wall(t),
            IMPACT => self.impact(t),
            g if g == self.end_slot() => Ok(self.at_end(t)),
            g => self.crossing(g - FIRST_CROSSING, t),
        }
    }

    fn energy(&self, t: Time) -> Option<f64> {
        let s = &self.string;
        let (mut energy, mut end) = (0.0, 0.0);
        for (p, a, b) in self.extents(t.value()) {
            energy += s.energy_density(p) * (b - a);
            end += p.strain * (b - a);
        }
        Some(energy - s.end_force() * end)
    }
}

impl StringModel for FrontTracking {
    /// The state at position `x` and time `t` (the piece to the right of a
    /// front exactly at `x`).
    fn piece_at(&self, x: f64, t: Time) -> Piece {
        let (t, c) = (t.value(), self.string.wave_speed);
        let i = self.fronts.partition_point(|f| f.at(t, c) <= x);
        self.pieces[i]
    }

    /// `y(x, t) = integral of eps from the wall to x`.
    fn displacement_at(&self, x: f64, t: Time) -> f64 {
        self.extents(t.value())
            .map(|(p, a, b)| p.strain * (b.min(x) - a).max(0.0))
            .sum()
    }

    /// Total momentum `integral of v`.
    fn momentum(&self, t: Time) -> f64 {
        self.extents(t.value())
            .map(|(p, a, b)| p.velocity * (b - a))
            .sum()
    }

    /// The momentum the end force and the wall (its pull and its impacts)
    /// have given since `t = 0`, added to the initial momentum: what
    /// [`StringModel::momentum`] must equal.
    fn momentum_by_impulses(&self, t: Time) -> f64 {
        let t = t.value();
        self.momentum_initial + self.string.end_force() * t + self.wall_given_until(t)
    }

    /// The coarse-grained fields of docs/physics.md s.6 at window centres
    /// `centres` and time `t`, by exact integrals over the pieces: windows
    /// of [`WINDOW_WIDTH`] clipped at the ends; mean strain and velocity;
    /// hidden energy = the window's energy less that of its means, per unit
    /// length (`v^2 / 2 + F_cr eps^2 / 2`: the linear terms cancel).
    fn coarse(&self, centres: &[f64], t: Time) -> Coarse {
        let (s, extents) = (&self.string, self.extents(t.value()).collect::<Vec<_>>());
        let mut coarse = Coarse {
            x: centres.to_vec(),
            strain: Vec::with_capacity(centres.len()),
            velocity: Vec::with_capacity(centres.len()),
            hidden_energy: Vec::with_capacity(centres.len()),
        };
        let quadratic =
            |p: Piece| 0.5 * (p.velocity.powi(2) + s.critical_load() * p.strain.powi(2));
        for &x in centres {
            let a = (x - 0.5 * WINDOW_WIDTH).max(s.wall());
            let b = (x + 0.5 * WINDOW_WIDTH).min(s.end());
            let (mut strain, mut velocity, mut energy) = (0.0, 0.0, 0.0);
            for &(p, lo, hi) in &extents {
                let w = (hi.min(b) - lo.max(a)).max(0.0);
                strain += p.strain * w;
                velocity += p.velocity * w;
                energy += quadratic(p) * w;
            }
            let width = b - a;
            let mean = Piece {
                strain: strain / width,
                velocity: velocity / width,
            };
            coarse.strain.push(mean.strain);
            coarse.velocity.push(mean.velocity);
            coarse.hidden_energy.push(energy / width - quadratic(mean));
        }
        coarse
    }

    fn profile(&self, points: &[f64], t: Time) -> Vec<(Piece, f64)> {
        let edges: Vec<f64> = self.edges(t.value()).collect();
        let (mut i, mut below) = (0, 0.0);
        points
            .iter()
            .map(|&x| {
                // The piece right of an edge exactly at x, as piece_at.
                while i + 1 < self.pieces.len() && edges[i + 1] <= x {
                    below += self.pieces[i].strain * (edges[i + 1] - edges[i]);
                    i += 1;
                }
                let p = self.pieces[i];
                (
                    p,
                    below + p.strain * (x.min(edges[i + 1]) - edges[i]).max(0.0),
                )
            })
            .collect()
    }
}
