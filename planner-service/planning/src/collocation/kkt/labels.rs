//! The block labelling of the KKT pattern: which mesh interval (block) and which pivot
//! group each KKT index belongs to, read off the [`Transcription`].

use crate::collocation::transcription::Transcription;

/// Bound magnitude pounce reads as "no bound" (`nlp_lower_bound_inf` / `_upper_`).
const POUNCE_INF: f64 = 1e19;

/// Block label of every KKT index (`< 0`: border), in pounce's KKT order
/// `[x not fixed | slacks | equality duals | inequality duals]`, and the pivot groups.
///
/// A pivot group is eliminated before the chain with its own small dense pivot: one
/// collocation node's controls with the defect rows of the states they drive (the control
/// rates: `psi` in 2-D, `Nz` and `mu` in 3-D). Its pivot `[[H_uu, J_uᵀ], [J_u, 0]]` is
/// nonsingular whenever the controls drive those rates (`J_u` is the interval's half
/// length), and taking the group out of its block shrinks the block's dense factorisation
/// (96 → 72 indices in 3-D, 42 → 30 in 2-D on the working mesh).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KktLabels {
    /// Block of every KKT index (`< 0`: border).
    pub blocks: Vec<i32>,
    /// Pivot group of every KKT index (`< 0`: none); empty: no groups.
    pub groups: Vec<i32>,
}

impl KktLabels {
    /// Labels with blocks only.
    pub fn plain(blocks: Vec<i32>) -> KktLabels {
        KktLabels {
            blocks,
            groups: Vec::new(),
        }
    }

    /// The labels of `tr`'s KKT: block `i` is mesh interval `i`; group `k` collocation node
    /// `k`'s controls and driven defect rows. Mirrors pounce's bound classification
    /// (`pounce_nlp::tnlp_adapter`): a variable with equal finite bounds is fixed and
    /// leaves the KKT; a constraint with equal finite bounds is an equality, any other an
    /// inequality with a slack.
    pub fn of(tr: &Transcription) -> KktLabels {
        let (nx, nu) = (tr.nx, tr.nu);
        let n_pts = tr.layout.lgr.len();
        let n_ctrl = tr.layout.control_nodes();
        let mut var = vec![-1i32; tr.n_vars()];
        for (k, node) in tr.layout.nodes.iter().enumerate() {
            let interval = (k / n_pts) as i32;
            // An interval's first point ends the previous interval (node 0 has none).
            let owner = if node.local == 0 {
                (interval - 1).max(0)
            } else {
                interval
            };
            for c in 0..nx {
                var[tr.state(k, c)] = owner;
            }
            for e in 0..nu {
                var[tr.control(k, e)] = interval;
            }
        }
        // The final node ends the last interval.
        let last = tr.layout.nodes.len();
        for c in 0..nx {
            var[tr.state(last, c)] = (last / n_pts) as i32 - 1;
        }
        let mut con = vec![-1i32; tr.n_cons()];
        for k in 0..n_ctrl {
            for c in 0..nx {
                con[k * nx + c] = (k / n_pts) as i32;
            }
        }
        let present = |lo: f64, hi: f64| lo > -POUNCE_INF && hi < POUNCE_INF;
        let fixed = |i: usize| present(tr.x_lo[i], tr.x_hi[i]) && tr.x_lo[i] == tr.x_hi[i];
        let equality: Vec<bool> = (0..tr.n_cons())
            .map(|r| present(tr.g_lo[r], tr.g_hi[r]) && tr.g_lo[r] == tr.g_hi[r])
            .collect();
        // A node's group: its controls (all free) and its driven defect rows (equalities).
        let driven = tr.vehicle.driven_states();
        let mut var_group = vec![-1i32; tr.n_vars()];
        let mut con_group = vec![-1i32; tr.n_cons()];
        for k in 0..n_ctrl {
            let controls_free = (0..nu).all(|e| !fixed(tr.control(k, e)));
            let rows_equal = driven.iter().all(|&c| equality[k * nx + c]);
            if driven.len() == nu && controls_free && rows_equal {
                for e in 0..nu {
                    var_group[tr.control(k, e)] = k as i32;
                }
                for &c in driven {
                    con_group[k * nx + c] = k as i32;
                }
            }
        }
        let (mut blocks, mut groups) = (Vec::new(), Vec::new());
        for (i, &l) in var.iter().enumerate() {
            if !fixed(i) {
                blocks.push(l);
                groups.push(var_group[i]);
            }
        }
        let inequalities = || (0..tr.n_cons()).filter(|&r| !equality[r]);
        for r in inequalities() {
            blocks.push(con[r]);
            groups.push(-1);
        }
        for r in (0..tr.n_cons()).filter(|&r| equality[r]) {
            blocks.push(con[r]);
            groups.push(con_group[r]);
        }
        for r in inequalities() {
            blocks.push(con[r]);
            groups.push(-1);
        }
        KktLabels { blocks, groups }
    }
}
