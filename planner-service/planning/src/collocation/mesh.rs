//! The mesh of a multi-phase LGR transcription and the layout of its nodes.
//!
//! Phase `p` spans `[T_p, T_{p+1}]` (`T_0` is the start time, `T_P` the final time) and is
//! cut into intervals with fixed *fractions* of the phase's duration, each holding `N` LGR
//! collocation points plus the interval's end (the next interval's first point). Nodes are
//! numbered over the whole trajectory: node 0 is the start, the last node is the final
//! state (the only node without a control). A phase's last node is the next phase's first
//! node, so state and time are continuous across phases by construction (the linkage).

use super::Lgr;

/// How each phase is cut into intervals.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// LGR points per interval.
    pub points: usize,
    /// Per phase, the intervals' fractions of the phase duration (each list sums to 1).
    pub phases: Vec<Vec<f64>>,
}

impl Mesh {
    /// Uniform intervals: phase `p` of expected duration `durations[p]` gets
    /// `ceil(duration / interval_s)` equal intervals (at least `min_intervals`).
    pub fn uniform(
        points: usize,
        durations: &[f64],
        interval_s: f64,
        min_intervals: usize,
    ) -> Mesh {
        let phases = durations
            .iter()
            .map(|&d| {
                let k = ((d / interval_s).ceil() as usize).max(min_intervals).max(1);
                vec![1.0 / k as f64; k]
            })
            .collect();
        Mesh { points, phases }
    }

    /// Total number of intervals.
    pub fn intervals(&self) -> usize {
        self.phases.iter().map(Vec::len).sum()
    }
}

/// Constants of one collocation node (every node but the last).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeInfo {
    /// Phase of the node.
    pub phase: usize,
    /// First node (support point 0) of the node's interval.
    pub interval_start: usize,
    /// Index of the node within its interval (0..N).
    pub local: usize,
    /// Position of the node in its phase, as a fraction of the phase duration.
    pub s: f64,
    /// Quadrature weight as a fraction of the phase duration: `w_i / 2 · fraction_k`, so
    /// the node's share of `∫ L dt` is `quad · Δ_p · L`.
    pub quad: f64,
    /// Half the interval's fraction: the defect is `D X - half · Δ_p · f`.
    pub half: f64,
}

/// The node layout of a mesh.
#[derive(Debug, Clone)]
pub struct Layout {
    pub lgr: Lgr,
    /// Every collocation node (all nodes but the last, final one).
    pub nodes: Vec<NodeInfo>,
    /// First node of each phase, plus the final node at the end (`phases + 1` entries).
    pub phase_start: Vec<usize>,
}

impl Layout {
    pub fn new(mesh: &Mesh) -> Layout {
        let lgr = Lgr::new(mesh.points);
        let n = mesh.points;
        let mut nodes = Vec::with_capacity(mesh.intervals() * n);
        let mut phase_start = Vec::with_capacity(mesh.phases.len() + 1);
        for (p, fractions) in mesh.phases.iter().enumerate() {
            phase_start.push(nodes.len());
            let mut begin = 0.0;
            for &frac in fractions {
                let interval_start = nodes.len();
                for i in 0..n {
                    let tau = lgr.support[i];
                    nodes.push(NodeInfo {
                        phase: p,
                        interval_start,
                        local: i,
                        s: begin + frac * (tau + 1.0) / 2.0,
                        quad: lgr.weights[i] / 2.0 * frac,
                        half: frac / 2.0,
                    });
                }
                begin += frac;
            }
        }
        phase_start.push(nodes.len());
        Layout {
            lgr,
            nodes,
            phase_start,
        }
    }

    /// Number of nodes with a state (collocation nodes + the final node).
    pub fn state_nodes(&self) -> usize {
        self.nodes.len() + 1
    }

    /// Number of collocation nodes (nodes with a control).
    pub fn control_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Number of phases.
    pub fn phases(&self) -> usize {
        self.phase_start.len() - 1
    }

    /// Fraction of the phase at node `k` (any node; the final node is 1 of the last phase).
    pub fn node_phase_fraction(&self, k: usize) -> (usize, f64) {
        if k == self.nodes.len() {
            (self.phases() - 1, 1.0)
        } else {
            (self.nodes[k].phase, self.nodes[k].s)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two phases of 3 and 2 intervals: node counts, phase starts, and the quadrature
    /// weights summing to one per phase (1e-14).
    #[test]
    fn layout_of_two_phases() {
        let mesh = Mesh {
            points: 4,
            phases: vec![vec![0.5, 0.25, 0.25], vec![0.5, 0.5]],
        };
        let l = Layout::new(&mesh);
        assert_eq!(l.control_nodes(), 20);
        assert_eq!(l.state_nodes(), 21);
        assert_eq!(l.phase_start, vec![0, 12, 20]);
        for p in 0..2 {
            let sum: f64 = l
                .nodes
                .iter()
                .filter(|n| n.phase == p)
                .map(|n| n.quad)
                .sum();
            assert!((sum - 1.0).abs() < 1e-14);
        }
        assert_eq!(l.nodes[12].s, 0.0);
        assert!(
            l.nodes
                .windows(2)
                .all(|w| w[0].phase != w[1].phase || w[1].s > w[0].s)
        );
        assert_eq!(l.node_phase_fraction(20), (1, 1.0));
    }
}
