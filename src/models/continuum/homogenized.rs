//! The homogenized string: a continuum that keeps the energy the chain's
//! micro-impacts hide, as an event-local model on the generic engine.
//!
//! Its state per unit length is the mean strain `e`, the mean velocity `v`
//! and the total energy `E = v^2 / 2 + u` (`rho = 1`), where the internal
//! energy `u` includes the rattling. Mass, momentum and energy are
//! conserved:
//!
//! ```text
//! e_t = v_x,   v_t = sigma_x,   E_t = (sigma v)_x,
//! ```
//!
//! with the mean force `sigma(e, u)` of the single mechanism's closed form
//! ([`super::rattle`]). A front that turns mean motion into rattling is a
//! shock of this system, found by the conservation laws alone.
//!
//! It is solved by finite volumes on equal cells: Rusanov fluxes bounded by
//! the cells' sound speeds, minmod reconstruction of `(e, v, u)` (falling
//! back to the cell's own state where a reconstruction leaves the law's
//! range), and Heun's two-stage step at a CFL number of [`CFL`]. At the
//! wall the flux is that of `v = 0`, at the loaded end that of the load,
//! each with the force or velocity an acoustic wave carries out of the last
//! cell. The fluxes telescope, so mass, momentum against its impulses and
//! energy against the load's work are kept to round-off whatever the
//! resolution; the cost per step is the number of cells, not of units.
//!
//! On the engine, each step is an internal event: the step fired at `t_k`
//! carries the cells to `t_{k+1}`, the next step or the next checkpoint
//! given at construction, whichever is sooner, and schedules itself there.
//! The cells are therefore always at the time of the next pending step, so
//! a sample taken at a checkpoint sees them exactly at its time (the engine
//! takes a sample before the events due at its time). The observations of
//! this model are of the cells at that time and meant for checkpoints only;
//! its energy elsewhere is `None`, so an audit or a trace off a checkpoint
//! shows a gap rather than a value of another time. (Steps land where the
//! model is told, not where the engine samples: a time-stepped model has
//! its state only at its steps.)

use std::ops::Range;

use crate::engine::{Direction, Fired, Guard, Labels, LocalModel};
use crate::models::chain::coarse::{Coarse, WINDOW_WIDTH};
use crate::models::continuum::{Continuum, Piece, StringModel, hugoniot, rattle};
use crate::time::Time;

/// Courant number of a step against the fastest cell.
pub const CFL: f64 = 0.4;

const STEP: &[Guard] = &[Guard::affine("step", Direction::Rising).as_internal()];

/// One cell's conserved densities: mean strain, momentum, energy.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Cell {
    strain: f64,
    velocity: f64,
    energy: f64,
}

/// The fluxes through every face, the wall's force, the fastest wave.
struct Fluxes {
    faces: Vec<[f64; 3]>,
    wall_force: f64,
    fastest: f64,
    /// Each cell's centre under the law.
    centres: Vec<f64>,
}

/// Compressions weaker than this (velocity over `c_b`, force over `F_cr`)
/// leave an end as acoustic waves; stronger ones as shocks.
const WEAK: f64 = 1e-6;

/// Times a step may be halved when a stage leaves the law's range.
const MAX_HALVINGS: u32 = 8;

/// A cell's state as the law reads it: force and sound speed too.
#[derive(Debug, Clone, Copy)]
struct Read {
    cell: Cell,
    force: f64,
    speed: f64,
    /// The law's centre, a starting point for nearby states.
    centre: f64,
}

/// The homogenized string on equal cells.
#[derive(Debug, Clone)]
pub struct Homogenized {
    string: Continuum,
    cells: Vec<Cell>,
    /// Each cell's centre under the law at the last step: where the next
    /// solve for it starts.
    hints: Vec<Option<f64>>,
    /// The time the cells are at.
    at: f64,
    /// Sorted times the steps land on (the run's samples and its end).
    checkpoints: Vec<f64>,
    /// Momentum the wall has given so far (the string starts at rest).
    wall_given: f64,
    steps: u64,
}

impl Homogenized {
    /// `string` on `cells` equal cells, at rest at strain `strain`, released
    /// at `t = 0`; its steps land on every one of `checkpoints`.
    pub fn new(
        string: Continuum,
        strain: f64,
        cells: usize,
        checkpoints: &[f64],
    ) -> Result<Self, String> {
        if cells == 0 {
            return Err("the homogenized string needs at least one cell".into());
        }
        if !(strain.is_finite() && strain > 0.0) {
            return Err(format!(
                "the homogenized string starts stretched (strain > 0), not at {strain:e}"
            ));
        }
        let f = string.critical_load();
        let cell = Cell {
            strain,
            velocity: 0.0,
            energy: f * (strain + 0.5 * strain * strain),
        };
        let mut checkpoints: Vec<f64> = checkpoints.iter().copied().filter(|t| *t > 0.0).collect();
        checkpoints.sort_by(f64::total_cmp);
        checkpoints.dedup();
        let model = Homogenized {
            cells: vec![cell; cells],
            hints: vec![None; cells],
            at: 0.0,
            checkpoints,
            wall_given: 0.0,
            steps: 0,
            string,
        };
        model.read(cell, None)?;
        Ok(model)
    }

    /// Heun steps taken so far.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    fn width(&self) -> f64 {
        self.string.length / self.cells.len() as f64
    }

    /// The force and sound speed of `cell`.
    fn read(&self, cell: Cell, hint: Option<f64>) -> Result<Read, String> {
        let f = self.string.critical_load();
        let g = (cell.energy - 0.5 * cell.velocity * cell.velocity) / f;
        let law = rattle::law(cell.strain, g, hint)?;
        Ok(Read {
            cell,
            force: f * (1.0 + law.centre),
            speed: self.string.wave_speed * law.speed,
            centre: law.centre,
        })
    }

    /// The flux `(-v, -sigma, -sigma v)` through each of the `n + 1` cell
    /// faces (the wall's first) and the fastest wave: a cell's sound speed
    /// or a shock leaving an end.
    fn fluxes(&self, cells: &[Cell]) -> Result<Fluxes, String> {
        let reads: Vec<Read> = cells
            .iter()
            .zip(&self.hints)
            .map(|(&c, &hint)| self.read(c, hint))
            .collect::<Result<_, _>>()?;
        let n = cells.len();
        let mut faces = Vec::with_capacity(n + 1);
        let mut fastest = reads.iter().fold(0.0, |m: f64, r| m.max(r.speed));
        let (wall_force, wall_speed) = self.at_wall(reads[0])?;
        fastest = fastest.max(wall_speed);
        faces.push([0.0, -wall_force, 0.0]);
        for i in 1..n {
            let (l, r) = self.faces(&reads, i);
            let a = l.speed.max(r.speed);
            let flux = |s: &Read| [-s.cell.velocity, -s.force, -s.force * s.cell.velocity];
            let (fl, fr) = (flux(&l), flux(&r));
            let (ul, ur) = (as_array(l.cell), as_array(r.cell));
            faces.push(std::array::from_fn(|k| {
                0.5 * (fl[k] + fr[k]) - 0.5 * a * (ur[k] - ul[k])
            }));
        }
        let load = self.string.load * self.string.critical_load();
        let (v_end, end_speed) = self.at_end(reads[n - 1], load)?;
        fastest = fastest.max(end_speed);
        faces.push([-v_end, -load, -load * v_end]);
        Ok(Fluxes {
            faces,
            wall_force,
            fastest,
            centres: reads.iter().map(|r| r.centre).collect(),
        })
    }

    /// The force at the wall (`v = 0` there) and the speed of the wave
    /// that leaves it: a shock if the string runs into the wall and
    /// rattles (or would be pushed below zero strain), else the force an
    /// acoustic wave brings out of the first cell (exact while elastic; a
    /// weak compression is an acoustic wave to second order).
    fn at_wall(&self, first: Read) -> Result<(f64, f64), String> {
        let (f, c) = (self.string.critical_load(), self.string.wave_speed);
        let elastic =
            first.centre == first.cell.strain && first.cell.strain + first.cell.velocity / c >= 0.0;
        if elastic || first.cell.velocity >= -WEAK * c {
            return Ok((first.force + first.speed * first.cell.velocity, first.speed));
        }
        let shock = hugoniot::from_wall(self.scaled(first.cell), first.force / f)?;
        let [e, _, _] = shock.behind;
        let v = first.cell.velocity / c;
        Ok((
            f * (first.force / f + v * v / (e - first.cell.strain)),
            shock.speed * c,
        ))
    }

    /// The velocity of the loaded end and the speed of the wave that leaves
    /// it: a shock if the load is below the force of the last cell and the
    /// string rattles there (or the load is below `F_cr`, which would push
    /// an elastic string below zero strain), else the velocity an acoustic
    /// wave brings out.
    fn at_end(&self, last: Read, load: f64) -> Result<(f64, f64), String> {
        let (f, c) = (self.string.critical_load(), self.string.wave_speed);
        let elastic = last.centre == last.cell.strain && load >= f;
        if elastic || load >= last.force - WEAK * f {
            return Ok((
                last.cell.velocity + (load - last.force) / last.speed,
                last.speed,
            ));
        }
        let shock = hugoniot::from_end(self.scaled(last.cell), last.force / f, load / f)?;
        Ok((shock.behind[1] * c, -shock.speed * c))
    }

    /// `cell` in the units of [`hugoniot`]: velocities over `c_b`, energies
    /// over `F_cr`.
    fn scaled(&self, cell: Cell) -> [f64; 3] {
        [
            cell.strain,
            cell.velocity / self.string.wave_speed,
            cell.energy / self.string.critical_load(),
        ]
    }

    /// The states either side of face `i` (between cells `i - 1` and `i`):
    /// minmod-limited slopes of `(e, v, u)`, or the cells' own states
    /// where a reconstruction falls outside the law's range.
    fn faces(&self, reads: &[Read], i: usize) -> (Read, Read) {
        let prim = |k: usize| {
            let c = reads[k].cell;
            [
                c.strain,
                c.velocity,
                c.energy - 0.5 * c.velocity * c.velocity,
            ]
        };
        let slope = |k: usize| -> [f64; 3] {
            if k == 0 || k + 1 == reads.len() {
                return [0.0; 3];
            }
            let (a, b, c) = (prim(k - 1), prim(k), prim(k + 1));
            std::array::from_fn(|j| minmod(b[j] - a[j], c[j] - b[j]))
        };
        let side = |k: usize, sign: f64| -> Option<Read> {
            let (p, s) = (prim(k), slope(k));
            let w: [f64; 3] = std::array::from_fn(|j| p[j] + sign * 0.5 * s[j]);
            let cell = Cell {
                strain: w[0],
                velocity: w[1],
                energy: w[2] + 0.5 * w[1] * w[1],
            };
            self.read(cell, Some(reads[k].centre)).ok()
        };
        (
            side(i - 1, 1.0).unwrap_or(reads[i - 1]),
            side(i, -1.0).unwrap_or(reads[i]),
        )
    }

    /// `cells + dt * (rate of change)` by `fluxes`.
    fn euler(&self, cells: &[Cell], fluxes: &Fluxes, dt: f64) -> Vec<Cell> {
        let r = dt / self.width();
        let f = &fluxes.faces;
        cells
            .iter()
            .enumerate()
            .map(|(i, c)| Cell {
                strain: c.strain - r * (f[i + 1][0] - f[i][0]),
                velocity: c.velocity - r * (f[i + 1][1] - f[i][1]),
                energy: c.energy - r * (f[i + 1][2] - f[i][2]),
            })
            .collect()
    }

    /// One Heun step, at most to `until`: as long as the fastest wave
    /// allows, halved while a stage leaves the law's range.
    fn step(&mut self, until: f64) -> Result<(), String> {
        let first = self.fluxes(&self.cells)?;
        let mut dt = (CFL * self.width() / first.fastest).min(until - self.at);
        let mut halvings = 0;
        let (next, second) = loop {
            let one = self.euler(&self.cells, &first, dt);
            let step = self.fluxes(&one).and_then(|second| {
                let two = self.euler(&one, &second, dt);
                let next: Vec<Cell> = self
                    .cells
                    .iter()
                    .zip(&two)
                    .map(|(c, b)| Cell {
                        strain: 0.5 * (c.strain + b.strain),
                        velocity: 0.5 * (c.velocity + b.velocity),
                        energy: 0.5 * (c.energy + b.energy),
                    })
                    .collect();
                match next.iter().position(|&c| !self.admissible(c)) {
                    None => Ok((next, second)),
                    Some(i) => Err(format!(
                        "cell {i} would leave the law's range (mean strain {:e})",
                        next[i].strain
                    )),
                }
            });
            match step {
                Ok(done) => break done,
                Err(why) if halvings == MAX_HALVINGS => {
                    return Err(format!("{why} (with the step halved {MAX_HALVINGS} times)"));
                }
                Err(_) => {
                    dt *= 0.5;
                    halvings += 1;
                }
            }
        };
        self.cells = next;
        self.wall_given -= 0.5 * (first.wall_force + second.wall_force) * dt;
        self.hints = second.centres.into_iter().map(Some).collect();
        self.at = if self.at + dt >= until {
            until
        } else {
            self.at + dt
        };
        self.steps += 1;
        Ok(())
    }

    /// Whether the law can read `cell`: a positive mean strain and an
    /// energy not below the elastic energy of its mean (no negative
    /// rattling), as [`rattle::centre`] requires.
    fn admissible(&self, cell: Cell) -> bool {
        let g = (cell.energy - 0.5 * cell.velocity * cell.velocity) / self.string.critical_load();
        let e = cell.strain;
        e > 0.0 && g - e - 0.5 * e * e >= -1e-12 * g.abs().max(e) && g.is_finite()
    }

    fn cell_index(&self, x: f64) -> usize {
        let i = ((x - self.string.wall()) / self.width()).floor();
        (i.max(0.0) as usize).min(self.cells.len() - 1)
    }
}

fn as_array(c: Cell) -> [f64; 3] {
    [c.strain, c.velocity, c.energy]
}

fn minmod(a: f64, b: f64) -> f64 {
    if a * b <= 0.0 {
        0.0
    } else if a.abs() < b.abs() {
        a
    } else {
        b
    }
}

impl LocalModel for Homogenized {
    fn mode_name(&self) -> &'static str {
        "string"
    }

    fn guards(&self) -> &[Guard] {
        STEP
    }

    fn predict(&self, _: usize, now: Time) -> Result<Option<Time>, String> {
        let due = self.checkpoints.last().is_some_and(|&end| self.at < end);
        Ok(due.then(|| Time::new(self.at.max(now.value()))))
    }

    fn fire(&mut self, _: usize, _: Time) -> Result<Fired, String> {
        let next = self
            .checkpoints
            .iter()
            .copied()
            .find(|&c| c > self.at)
            .expect("a step is predicted only before the last checkpoint");
        self.step(next)?;
        Ok(Fired {
            affects: Range { start: 0, end: 1 },
            labels: Labels::NONE,
        })
    }

    fn energy(&self, t: Time) -> Option<f64> {
        if t.value() != self.at {
            return None;
        }
        let h = self.width();
        let stored: f64 = self.cells.iter().map(|c| c.energy * h).sum();
        let load = self.string.load * self.string.critical_load();
        Some(stored - load * self.right_end(Time::new(self.at)))
    }
}

impl StringModel for Homogenized {
    fn piece_at(&self, x: f64, _: Time) -> Piece {
        let c = self.cells[self.cell_index(x)];
        Piece {
            strain: c.strain,
            velocity: c.velocity,
        }
    }

    fn displacement_at(&self, x: f64, _: Time) -> f64 {
        let h = self.width();
        let i = self.cell_index(x);
        let whole: f64 = self.cells[..i].iter().map(|c| c.strain * h).sum();
        let part = (x - self.string.wall() - i as f64 * h).clamp(0.0, h);
        whole + self.cells[i].strain * part
    }

    fn momentum(&self, _: Time) -> f64 {
        self.cells.iter().map(|c| c.velocity).sum::<f64>() * self.width()
    }

    fn momentum_by_impulses(&self, _: Time) -> f64 {
        let load = self.string.load * self.string.critical_load();
        load * self.at + self.wall_given
    }

    fn coarse(&self, centres: &[f64], _: Time) -> Coarse {
        let (h, f) = (self.width(), self.string.critical_load());
        let mut coarse = Coarse {
            x: centres.to_vec(),
            strain: Vec::with_capacity(centres.len()),
            velocity: Vec::with_capacity(centres.len()),
            hidden_energy: Vec::with_capacity(centres.len()),
        };
        for &x in centres {
            let a = (x - 0.5 * WINDOW_WIDTH).max(self.string.wall());
            let b = (x + 0.5 * WINDOW_WIDTH).min(self.string.end());
            let (mut e, mut v, mut energy) = (0.0, 0.0, 0.0);
            for i in self.cell_index(a)..=self.cell_index(b) {
                let lo = self.string.wall() + i as f64 * h;
                let w = ((lo + h).min(b) - lo.max(a)).max(0.0);
                let c = self.cells[i];
                e += c.strain * w;
                v += c.velocity * w;
                energy += c.energy * w;
            }
            let width = b - a;
            let (e, v) = (e / width, v / width);
            coarse.strain.push(e);
            coarse.velocity.push(v);
            coarse
                .hidden_energy
                .push(energy / width - 0.5 * v * v - f * (0.5 * e * e + e));
        }
        coarse
    }

    fn profile(&self, points: &[f64], t: Time) -> Vec<(Piece, f64)> {
        let h = self.width();
        let (mut i, mut below) = (0, 0.0);
        points
            .iter()
            .map(|&x| {
                let at = self.cell_index(x);
                while i < at {
                    below += self.cells[i].strain * h;
                    i += 1;
                }
                let part = (x - self.string.wall() - at as f64 * h).clamp(0.0, h);
                (self.piece_at(x, t), below + self.cells[at].strain * part)
            })
            .collect()
    }
}
