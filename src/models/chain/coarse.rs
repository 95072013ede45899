//! Coarse-grained fields of a chain (docs/physics.md s.6): the averages over
//! many units that stay reproducible past the chaos horizon, and by which a
//! chain is compared with a continuum.
//!
//! Windows of width [`WINDOW_WIDTH`] are centred on each node (clipped at
//! the ends). Window strain = displacement difference across the window
//! over its width (the mean unit strain); window velocity = the
//! mass-weighted mean node velocity; hidden energy = the window's energy
//! minus the energy of its mean fields, per unit length (the rattling the
//! mean fields do not see). The front is the leftmost window centre whose
//! strain has dropped below the undisturbed value by [`FRONT_DROP`].

use super::Chain;

/// Width of a coarse-graining window, in the scene's length units.
pub const WINDOW_WIDTH: f64 = 0.1;

/// How far below the undisturbed strain a window must drop to be behind
/// the front.
pub const FRONT_DROP: f64 = 0.008;

/// The coarse fields at the nodes `x` (the wall's included).
#[derive(Debug, Clone, PartialEq)]
pub struct Coarse {
    /// Window centres, in the scene's length units (the wall at `-length / 2`).
    pub x: Vec<f64>,
    /// Window strain at each centre: the mean unit strain over the window.
    pub strain: Vec<f64>,
    /// Window velocity at each centre: the mass-weighted mean node velocity.
    pub velocity: Vec<f64>,
    /// Hidden energy per unit length at each centre: the window's energy
    /// minus the energy of its mean fields.
    pub hidden_energy: Vec<f64>,
}

impl Coarse {
    /// The fields of `chain` (of total length `length`) with unit gaps
    /// `gaps` and node velocities `velocities`, at every node `x_j` (the
    /// wall is node 0): the window around `x_j` holds the `h` units on
    /// each side, `2 h` cells as close to [`WINDOW_WIDTH`] as whole units
    /// allow (at least one each side), fewer at the ends. Velocities are
    /// averaged over the window's mass (its end nodes half each), centred
    /// on `x_j` too.
    pub fn of(chain: &Chain, length: f64, gaps: &[f64], velocities: &[f64]) -> Self {
        let n = chain.units;
        let cell = length / n as f64;
        let unit_length = chain.unit_length();
        let half = ((0.5 * WINDOW_WIDTH / cell).round() as usize).max(1);
        let mut coarse = Coarse {
            x: Vec::with_capacity(n + 1),
            strain: Vec::with_capacity(n + 1),
            velocity: Vec::with_capacity(n + 1),
            hidden_energy: Vec::with_capacity(n + 1),
        };
        for node in 0..=n {
            // Units node - h + 1 ..= node + h (1-based), 0-based below;
            // each unit's velocity is that of its node away from the wall.
            let (lo, hi) = (
                (node + 1).saturating_sub(half).max(1) - 1,
                node.saturating_add(half).min(n) - 1,
            );
            let count = (hi - lo + 1) as f64;
            let d = &gaps[lo..=hi];
            let mean_gap = d.iter().sum::<f64>() / count;
            // The window's mass: its inner nodes whole, the two at its ends
            // (nodes lo and hi + 1, 1-based) half each; the wall's node is
            // at rest.
            let weighted = || {
                (lo..=hi + 1).map(|j| {
                    let w = if j == lo || j == hi + 1 { 0.5 } else { 1.0 };
                    (w, if j == 0 { 0.0 } else { velocities[j - 1] })
                })
            };
            let mean_velocity = weighted().map(|(w, v)| w * v).sum::<f64>() / count;
            let elastic: f64 = d
                .iter()
                .map(|d| 0.5 * chain.stiffness * (d - mean_gap).powi(2))
                .sum();
            let kinetic: f64 = weighted()
                .map(|(w, v)| 0.5 * chain.mass * w * (v - mean_velocity).powi(2))
                .sum();
            let rattle = elastic + kinetic;
            coarse.x.push(-0.5 * length + node as f64 * cell);
            coarse.strain.push(mean_gap / unit_length);
            coarse.velocity.push(mean_velocity);
            coarse.hidden_energy.push(rattle / (count * cell));
        }
        coarse
    }

    /// The leftmost window centre whose strain is below `undisturbed -
    /// FRONT_DROP`, if any.
    pub fn front(&self, undisturbed: f64) -> Option<f64> {
        self.strain
            .iter()
            .position(|&e| e < undisturbed - FRONT_DROP)
            .map(|i| self.x[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_uniform_chain_has_its_own_strain_and_no_hidden_energy() {
        let chain = Chain::in_scene_units(40, 2.0, 1.0, 0.0, true);
        let unit = chain.unit_length();
        let c = Coarse::of(&chain, 2.0, &vec![0.1 * unit; 40], &vec![0.3; 40]);
        assert!(c.strain.iter().all(|e| (e - 0.1).abs() < 1e-15));
        // Windows clear of the wall (whose node is at rest): h = 1 here.
        assert!(c.velocity[2..].iter().all(|v| (v - 0.3).abs() < 1e-15));
        assert!(c.hidden_energy[2..].iter().all(|h| h.abs() < 1e-15));
        // Around the wall the node at rest is part of the window's mass.
        assert!((c.velocity[0] - 0.15).abs() < 1e-15 && c.hidden_energy[0] > 0.0);
        assert_eq!(c.front(0.1), None);
    }

    #[test]
    fn alternating_rattle_shows_as_hidden_energy_and_a_front() {
        // Units 21..40 (0-based 20..39) alternate between strain 0 and 0.1
        // with node velocities -+0.2: mean strain 0.05, behind the front.
        let n = 40;
        let chain = Chain::in_scene_units(n, 2.0, 1.0, 0.0, true);
        let unit = chain.unit_length();
        let gaps: Vec<f64> = (0..n)
            .map(|i| {
                if i < 20 || i % 2 == 0 {
                    0.1 * unit
                } else {
                    0.0
                }
            })
            .collect();
        let v: Vec<f64> = (0..n)
            .map(|i| match i {
                _ if i < 20 => 0.0,
                _ if i % 2 == 0 => 0.2,
                _ => -0.2,
            })
            .collect();
        let c = Coarse::of(&chain, 2.0, &gaps, &v);
        // Cells are 0.05 long: the window of width 0.1 around node 38
        // (x = 0.9) holds units 38 and 39 (0-based 37 and 38).
        assert_eq!(c.x.len(), n + 1);
        assert!((c.x[38] - 0.9).abs() < 1e-12);
        assert!((c.strain[38] - 0.05).abs() < 1e-12, "{}", c.strain[38]);
        assert!(c.velocity[38].abs() < 1e-15);
        // By hand (k = 20, m = 0.05, unit length u = 0.05, cell = 0.05):
        // gaps [0, 0.1 u] deviate by -+0.05 u, velocities [-0.2, 0.2] by
        // -+0.2; the pair holds k (0.05 u)^2 + m 0.2^2 over a length 0.1.
        let by_hand = (20.0 * (0.05f64 * 0.05).powi(2) + 0.05 * 0.04) / 0.1;
        assert!(
            (c.hidden_energy[38] - by_hand).abs() < 1e-15,
            "{}",
            c.hidden_energy[38]
        );
        // The front: the first window holding a shut unit, around node 21
        // (units 21 and 22, 0-based 20 and 21: strains 0.1 and 0).
        let front = c.front(0.1).unwrap();
        assert!((front - c.x[21]).abs() < 1e-12, "front at {front}");
    }
}
