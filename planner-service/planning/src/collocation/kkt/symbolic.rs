//! The symbolic analysis: [`Workspace::new`] reads the pattern under the labels, checks
//! that they describe it, and places every block, pivot group and nonzero in the
//! workspace's buffers, in named steps.

use pounce_rs::Index;

use crate::linalg::bunch_kaufman;

use super::workspace::{Block, Group, Workspace};

/// Largest block the dense path takes.
const MAX_BLOCK: usize = 600;

/// Largest border the dense path takes: the dense border factorisation grows as its
/// cube. With the interval ends in the blocks the collocation's borders hold only the
/// phase times and the phase-order and rendezvous rows (at most `3 · phases + 3` indices,
/// `tests/kkt.rs`); when the interval
/// ends were in the border (74-152 in 2-D, 200-430 in 3-D), the 3-D ones planned no
/// faster than FERAL.
const MAX_BORDER: usize = 160;

/// Where every KKT index goes: a block (compact ids, in label order: the chain's order),
/// a pivot group (compact ids, in label order) or the border, and its place there.
struct Partition {
    /// Blocks and pivot groups.
    count: usize,
    g_count: usize,
    /// Of every KKT index, its block and its group (`usize::MAX`: none) and its position
    /// in its block, group or the border.
    block_of: Vec<usize>,
    group_of: Vec<usize>,
    local: Vec<usize>,
    /// The order of every block.
    sizes: Vec<usize>,
    /// KKT index of each border position.
    border: Vec<usize>,
    /// Of every group, its block and its KKT indices.
    g_block: Vec<usize>,
    g_members: Vec<Vec<usize>>,
}

impl Partition {
    /// The partition `labels` and `groups` (empty: none) describe, or `None` when a group
    /// lies across blocks or in the border, no index is in a block, or a block or the
    /// border is too large.
    fn of(dim: usize, labels: &[i32], groups: &[i32]) -> Option<Partition> {
        let in_group = |i: usize| groups.get(i).is_some_and(|&g| g >= 0);
        // Compact group ids (in label order) and block ids (keeping the label order, the
        // chain's order) of the indices outside the groups.
        let g_max = groups.iter().copied().max().unwrap_or(-1);
        let mut g_remap = vec![usize::MAX; (g_max + 1).max(0) as usize];
        let mut g_count = 0;
        for &g in groups.iter().filter(|&&g| g >= 0) {
            if g_remap[g as usize] == usize::MAX {
                g_remap[g as usize] = g_count;
                g_count += 1;
            }
        }
        let max = labels.iter().copied().max().unwrap_or(-1);
        if max < 0 {
            return None;
        }
        let mut present = vec![false; max as usize + 1];
        for (i, &l) in labels.iter().enumerate() {
            if l >= 0 && !in_group(i) {
                present[l as usize] = true;
            }
        }
        let mut remap = vec![usize::MAX; present.len()];
        let mut count = 0;
        for (slot, &p) in remap.iter_mut().zip(&present) {
            if p {
                *slot = count;
                count += 1;
            }
        }
        let mut block_of = vec![usize::MAX; dim];
        let mut group_of = vec![usize::MAX; dim];
        let mut local = vec![0usize; dim];
        let mut sizes = vec![0usize; count];
        let mut border = Vec::new();
        let mut g_block = vec![usize::MAX; g_count];
        let mut g_members: Vec<Vec<usize>> = vec![Vec::new(); g_count];
        for (i, &l) in labels.iter().enumerate() {
            if in_group(i) {
                // A group lies inside one block (it is eliminated with that block).
                let g = g_remap[groups[i] as usize];
                let b = if l >= 0 {
                    remap[l as usize]
                } else {
                    usize::MAX
                };
                if b == usize::MAX || (g_block[g] != usize::MAX && g_block[g] != b) {
                    return None;
                }
                g_block[g] = b;
                group_of[i] = g;
                local[i] = g_members[g].len();
                g_members[g].push(i);
            } else if l < 0 {
                local[i] = border.len();
                border.push(i);
            } else {
                let b = remap[l as usize];
                block_of[i] = b;
                local[i] = sizes[b];
                sizes[b] += 1;
            }
        }
        let nb = border.len();
        if nb > MAX_BORDER || sizes.iter().any(|&s| s > MAX_BLOCK) {
            return None;
        }
        Some(Partition {
            count,
            g_count,
            block_of,
            group_of,
            local,
            sizes,
            border,
            g_block,
            g_members,
        })
    }

    /// The groups ordered by block (then by id), and where each block's share of them
    /// starts in that order (`count + 1` entries).
    fn group_order(&self) -> (Vec<usize>, Vec<usize>) {
        let mut g_order: Vec<usize> = (0..self.g_count).collect();
        g_order.sort_by_key(|&g| (self.g_block[g], g));
        let mut g_first_of = vec![0usize; self.count + 1];
        for &g in &g_order {
            g_first_of[self.g_block[g] + 1] += 1;
        }
        for b in 0..self.count {
            g_first_of[b + 1] += g_first_of[b];
        }
        (g_order, g_first_of)
    }
}

/// What couples to what, per block: the border columns it touches (increasing, local to
/// the border) and its links (its predecessor's local indices it touches, increasing);
/// per group, its neighbours (KKT indices, increasing).
struct Couplings {
    touches: Vec<Vec<usize>>,
    linked: Vec<Vec<usize>>,
    nbrs: Vec<Vec<usize>>,
}

impl Couplings {
    /// The couplings of the pattern `(ia, ja)` (1-based) under `part`, from the pattern
    /// and from the groups' fill (every pair of a group's neighbours); `None` on an index
    /// out of range or an entry coupling two blocks that are not neighbours, or two
    /// groups.
    fn of(part: &Partition, dim: usize, ia: &[Index], ja: &[Index]) -> Option<Couplings> {
        let (count, block_of, local) = (part.count, &part.block_of, &part.local);
        let mut touches: Vec<Vec<usize>> = vec![Vec::new(); count];
        let mut linked: Vec<Vec<usize>> = vec![Vec::new(); count];
        let mut nbrs: Vec<Vec<usize>> = vec![Vec::new(); part.g_count];
        let mut record = |r: usize, c: usize| -> Option<()> {
            match (block_of[r], block_of[c]) {
                (usize::MAX, usize::MAX) => {}
                (usize::MAX, b) => touches[b].push(local[r]),
                (b, usize::MAX) => touches[b].push(local[c]),
                (br, bc) if br == bc + 1 => linked[br].push(local[c]),
                (br, bc) if bc == br + 1 => linked[bc].push(local[r]),
                (br, bc) if br != bc => return None,
                _ => {}
            }
            Some(())
        };
        for (&r, &c) in ia.iter().zip(ja) {
            let (r, c) = (r as usize, c as usize);
            if r == 0 || c == 0 || r > dim || c > dim {
                return None;
            }
            let (r, c) = (r - 1, c - 1);
            match (part.group_of[r], part.group_of[c]) {
                (usize::MAX, usize::MAX) => record(r, c)?,
                (gr, gc) if gr == gc => {}
                (usize::MAX, g) => nbrs[g].push(r),
                (g, usize::MAX) => nbrs[g].push(c),
                _ => return None,
            }
        }
        for list in &mut nbrs {
            list.sort_unstable();
            list.dedup();
            for i in 0..list.len() {
                for j in 0..=i {
                    record(list[i], list[j])?;
                }
            }
        }
        // A block linked to its predecessor inherits its border columns (fill).
        for b in 0..count {
            linked[b].sort_unstable();
            linked[b].dedup();
            if b > 0 && !linked[b].is_empty() {
                let inherited = touches[b - 1].clone();
                touches[b].extend(inherited);
            }
            touches[b].sort_unstable();
            touches[b].dedup();
        }
        Some(Couplings {
            touches,
            linked,
            nbrs,
        })
    }
}

/// The buffer sizes the placement of the blocks and the groups comes to.
#[derive(Default)]
struct Extents {
    /// The blocks' total order, and the lengths of the `W` and `Z` parts.
    first: usize,
    w_len: usize,
    z_len: usize,
    /// Largest link count, border-column count, `n · l`, `n · m` and `n_{k-1} · l` of a
    /// block.
    max_l: usize,
    max_m: usize,
    max_nl: usize,
    max_nm: usize,
    max_zl: usize,
    /// The end of the groups' `G` and `B` in `dense`, the length of `g_y` and of
    /// `g_inv`, the largest `q · nn` and the largest `q`.
    g_at: usize,
    y_len: usize,
    inv_len: usize,
    max_qn: usize,
    largest_q: usize,
}

impl Workspace {
    /// The workspace for the pattern `(ia, ja)` (1-based) under the block `labels` and
    /// the pivot `groups` (empty: none), or `None` when they do not describe it (an entry
    /// coupling two blocks that are not neighbours in label order, or two groups; a group
    /// across blocks or in the border; a block or border too large).
    pub(super) fn new(
        dim: usize,
        ia: &[Index],
        ja: &[Index],
        labels: &[i32],
        groups: &[i32],
    ) -> Option<Workspace> {
        if labels.len() != dim || ia.len() != ja.len() {
            return None;
        }
        if !groups.is_empty() && groups.len() != dim {
            return None;
        }
        let mut part = Partition::of(dim, labels, groups)?;
        let couplings = Couplings::of(&part, dim, ia, ja)?;
        let mut ws = Workspace {
            border: std::mem::take(&mut part.border),
            ..Workspace::default()
        };
        let (g_order, g_first_of) = part.group_order();
        let mut ext = ws.place_blocks(&part, &couplings, &g_first_of);
        let g_index = ws.place_groups(&part, &couplings.nbrs, &g_order, &g_first_of, &mut ext);
        ws.allocate(&ext, part.count, dim, ia, ja);
        ws.place_group_fill(&part)?;
        let owners = ws.place_nonzeros(&part, ia, ja, &g_index)?;
        ws.order_by_owner(&owners, part.count);
        ws.in_bounds(dim).then_some(ws)
    }

    /// Places the blocks (their `A`, `C`, `W`, `Y` and `Z`, border columns and links, one
    /// after another in block order) and their members.
    fn place_blocks(&mut self, part: &Partition, cp: &Couplings, g_first_of: &[usize]) -> Extents {
        let (sizes, touches, linked) = (&part.sizes, &cp.touches, &cp.linked);
        let (mut first, mut a_len, mut c_len, mut w_len, mut z_len) = (0, 0, 0, 0, 0);
        let (mut max_l, mut max_nl, mut max_nm, mut max_zl, mut max_m) = (0, 0, 0, 0, 0);
        for b in 0..part.count {
            let (n, m, l) = (sizes[b], touches[b].len(), linked[b].len());
            self.blocks.push(Block {
                n,
                first,
                a_off: a_len,
                m,
                b_first: self.border_cols.len(),
                w_off: w_len,
                y_off: w_len,
                l,
                l_first: self.links.len(),
                c_off: c_len,
                z_off: z_len,
                g_first: g_first_of[b],
                g_count: g_first_of[b + 1] - g_first_of[b],
                gs_off: 0,
                gs_len: 0,
            });
            for &col in &touches[b] {
                let prev = if b > 0 && l > 0 {
                    touches[b - 1].binary_search(&col).unwrap_or(usize::MAX)
                } else {
                    usize::MAX
                };
                self.prev_col.push(prev);
            }
            self.border_cols.extend_from_slice(&touches[b]);
            self.links.extend_from_slice(&linked[b]);
            first += n;
            a_len += n * n;
            c_len += n * l;
            w_len += n * m;
            if l > 0 {
                z_len += sizes[b - 1] * l;
                max_zl = max_zl.max(sizes[b - 1] * l);
            }
            max_l = max_l.max(l);
            max_m = max_m.max(m);
            max_nl = max_nl.max(n * l);
            max_nm = max_nm.max(n * m);
        }
        self.c_base = a_len;
        self.w_base = a_len + c_len;
        self.members = vec![0; first];
        let mut fill: Vec<usize> = self.blocks.iter().map(|b| b.first).collect();
        for (i, &b) in part.block_of.iter().enumerate() {
            if b != usize::MAX {
                self.members[fill[b]] = i;
                fill[b] += 1;
            }
        }
        self.s_off = a_len + c_len + w_len;
        Extents {
            first,
            w_len,
            z_len,
            max_l,
            max_m,
            max_nl,
            max_nm,
            max_zl,
            ..Extents::default()
        }
    }

    /// Places the groups' `G` and `B` after `S`, block by block, and their members and
    /// neighbours; the position of every group (by id) in `groups`.
    fn place_groups(
        &mut self,
        part: &Partition,
        nbrs: &[Vec<usize>],
        g_order: &[usize],
        g_first_of: &[usize],
        ext: &mut Extents,
    ) -> Vec<usize> {
        let nb = self.border.len();
        let mut g_at = self.s_off + nb * nb;
        let (mut y_len, mut max_qn, mut largest_q, mut inv_len) = (0, 0, 0, 0);
        let mut g_index = vec![0usize; part.g_count];
        for (b, blk) in self.blocks.iter_mut().enumerate() {
            blk.gs_off = g_at;
            for &g in &g_order[g_first_of[b]..g_first_of[b + 1]] {
                let (q, nn) = (part.g_members[g].len(), nbrs[g].len());
                g_index[g] = self.groups.len();
                self.groups.push(Group {
                    q,
                    first: self.g_members.len(),
                    nn,
                    n_first: self.g_nbrs.len(),
                    g_off: g_at,
                    y_off: y_len,
                    inv_off: inv_len,
                    f_first: 0,
                });
                inv_len += q * q;
                self.g_members.extend_from_slice(&part.g_members[g]);
                self.g_nbrs.extend_from_slice(&nbrs[g]);
                g_at += q * q + q * nn;
                y_len += q * nn;
                max_qn = max_qn.max(q * nn);
                largest_q = largest_q.max(q);
            }
            blk.gs_len = g_at - blk.gs_off;
        }
        ext.g_at = g_at;
        ext.y_len = y_len;
        ext.inv_len = inv_len;
        ext.max_qn = max_qn;
        ext.largest_q = largest_q;
        g_index
    }

    /// Allocates every buffer at its size (`count` blocks), and keeps the pattern for
    /// the residuals.
    fn allocate(&mut self, ext: &Extents, count: usize, dim: usize, ia: &[Index], ja: &[Index]) {
        let nb = self.border.len();
        let (first, max_l) = (ext.first, ext.max_l);
        self.dense = vec![0.0; ext.g_at];
        self.y = vec![0.0; ext.w_len];
        self.z = vec![0.0; ext.z_len];
        self.piv = vec![0; first + nb];
        self.g_w = vec![0.0; ext.max_nm];
        let largest = self.blocks.iter().map(|b| b.n).max().unwrap_or(0);
        let largest = largest.max(nb).max(ext.largest_q);
        self.bk_work = vec![0.0; bunch_kaufman::work_len(largest)];
        self.g_l = vec![0.0; ext.max_zl];
        self.m_link = vec![0.0; max_l * max_l];
        self.y_link = vec![0.0; max_l * ext.max_m];
        self.cm = vec![0.0; ext.max_nl];
        self.work = vec![0.0; first];
        self.work_b = vec![0.0; nb];
        self.ctx = vec![0.0; max_l];
        self.rhs = vec![0.0; dim];
        self.res = vec![0.0; dim];
        self.g_piv = vec![0; self.g_members.len()];
        self.g_y = vec![0.0; ext.y_len];
        self.g_b = vec![0.0; ext.max_qn];
        self.g_work = vec![0.0; self.g_members.len()];
        self.g_inv = vec![0.0; ext.inv_len];
        self.g_nz = vec![0; self.g_nbrs.len()];
        self.g_nz_len = vec![0; self.groups.len()];
        self.first_dual = usize::MAX;
        self.block_duals = vec![0; count];
        self.group_duals = vec![0; count];
        self.fill_rank_any = vec![0; count];
        self.fill_rank_zero = vec![0; count];
        self.m_copy = vec![0.0; max_l * max_l];
        self.m_piv = vec![0; max_l];
        self.rows = ia.iter().map(|&r| (r - 1) as u32).collect();
        self.cols = ja.iter().map(|&c| (c - 1) as u32).collect();
    }

    /// Where an entry (r, c) outside the groups goes (lower triangle of each symmetric
    /// dense matrix), and which block takes it (its `A`, `C` or `W`; the block count:
    /// `S`).
    fn slot(&self, part: &Partition, r: usize, c: usize) -> Option<(usize, usize)> {
        let (block_of, local) = (&part.block_of, &part.local);
        let (count, nb) = (part.count, self.border.len());
        Some(match (block_of[r], block_of[c]) {
            (usize::MAX, usize::MAX) => {
                let (i, j) = (local[r].max(local[c]), local[r].min(local[c]));
                (self.s_off + i + j * nb, count)
            }
            (usize::MAX, b) | (b, usize::MAX) => {
                let (row, bcol) = if block_of[r] == b {
                    (local[r], local[c])
                } else {
                    (local[c], local[r])
                };
                let blk = self.blocks[b];
                let cols = &self.border_cols[blk.b_first..blk.b_first + blk.m];
                let j = cols.binary_search(&bcol).ok()?;
                (self.w_base + blk.w_off + row + j * blk.n, b)
            }
            (br, bc) if br != bc => {
                let (hi, row, prev) = if br > bc {
                    (br, local[r], local[c])
                } else {
                    (bc, local[c], local[r])
                };
                let blk = self.blocks[hi];
                let links = &self.links[blk.l_first..blk.l_first + blk.l];
                let j = links.binary_search(&prev).ok()?;
                (self.c_base + blk.c_off + row + j * blk.n, hi)
            }
            (b, _) => {
                let blk = self.blocks[b];
                let (i, j) = (local[r].max(local[c]), local[r].min(local[c]));
                (blk.a_off + i + j * blk.n, b)
            }
        })
    }

    /// The groups' fill destinations: for each group, where `B_iᵀ Y_j` is subtracted for
    /// each pair of its neighbours `j ≤ i`, column by column.
    fn place_group_fill(&mut self, part: &Partition) -> Option<()> {
        for gi in 0..self.groups.len() {
            let g = self.groups[gi];
            self.groups[gi].f_first = self.g_fill.len();
            for j in 0..g.nn {
                for i in j..g.nn {
                    let (r, c) = (self.g_nbrs[g.n_first + i], self.g_nbrs[g.n_first + j]);
                    let (d, _) = self.slot(part, r, c)?;
                    self.g_fill.push(d);
                }
            }
        }
        Some(())
    }

    /// The destination in `dense` of every input nonzero (`dest`), and the block that
    /// takes each (the block count: the border), returned.
    fn place_nonzeros(
        &mut self,
        part: &Partition,
        ia: &[Index],
        ja: &[Index],
        g_index: &[usize],
    ) -> Option<Vec<usize>> {
        let (group_of, local, g_block) = (&part.group_of, &part.local, &part.g_block);
        self.dest = Vec::with_capacity(ia.len());
        let mut owners = Vec::with_capacity(ia.len());
        for (&r, &c) in ia.iter().zip(ja) {
            let (r, c) = (r as usize - 1, c as usize - 1);
            let (d, owner) = match (group_of[r], group_of[c]) {
                (usize::MAX, usize::MAX) => self.slot(part, r, c)?,
                (gr, gc) if gr == gc => {
                    let g = self.groups[g_index[gr]];
                    let (i, j) = (local[r].max(local[c]), local[r].min(local[c]));
                    (g.g_off + i + j * g.q, g_block[gr])
                }
                (usize::MAX, gc) | (gc, usize::MAX) => {
                    let (member, other) = if group_of[r] == gc { (r, c) } else { (c, r) };
                    let g = self.groups[g_index[gc]];
                    let list = &self.g_nbrs[g.n_first..g.n_first + g.nn];
                    let j = list.binary_search(&other).ok()?;
                    (g.g_off + g.q * g.q + local[member] + j * g.q, g_block[gc])
                }
                _ => return None,
            };
            self.dest.push(d);
            owners.push(owner);
        }
        Some(owners)
    }

    /// Groups the nonzeros by the block that takes them (`owners`; the border last), so
    /// that each block is assembled just before it is needed, while it is in cache.
    fn order_by_owner(&mut self, owners: &[usize], count: usize) {
        self.owner_start = vec![0; count + 2];
        for &o in owners {
            self.owner_start[o + 1] += 1;
        }
        for b in 0..=count {
            self.owner_start[b + 1] += self.owner_start[b];
        }
        self.by_owner = vec![0; owners.len()];
        let mut fill = self.owner_start.clone();
        for (i, &o) in owners.iter().enumerate() {
            self.by_owner[fill[o]] = i as u32;
            fill[o] += 1;
        }
    }

    /// What the unchecked loops of `assemble`, `eliminate_groups` and `solve_refined`
    /// rely on: every destination (of a nonzero, of a group's fill) inside `dense`,
    /// every pattern index (checked by [`Couplings::of`]) below `dim`.
    fn in_bounds(&self, dim: usize) -> bool {
        !(self
            .dest
            .iter()
            .chain(&self.g_fill)
            .any(|&d| d >= self.dense.len())
            || self
                .rows
                .iter()
                .chain(&self.cols)
                .any(|&i| i as usize >= dim)
            || self.res.len() != dim)
    }
}
