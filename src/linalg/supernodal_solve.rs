//! A tree-parallel solve with faer's supernodal LDL^T factor.
//!
//! faer's `LdltRef::solve_in_place_with_conj` walks the supernodes one after the other (forward
//! substitution with the unit lower L, the diagonal D, backward substitution with L^T): on a
//! large factor that pass over L is bound by memory bandwidth and runs on one core. Here the
//! supernodes are scheduled on their elimination tree: subtrees that share no supernode are
//! independent, and are solved in parallel (`rayon::join`).
//!
//! Storage (faer 0.24, `SymbolicSupernodalCholesky`): supernode s holds the contiguous columns
//! `supernode_begin[s]..supernode_end[s]` (w of them) of the permuted matrix; its rows are those
//! columns followed by its pattern `row_idx[col_ptr_for_row_idx[s]..col_ptr_for_row_idx[s + 1]]`
//! (m rows, increasing, all past the supernode); its values are the (w + m) x w column-major
//! block `factor[col_ptr_for_val[s]..col_ptr_for_val[s + 1]]`, whose top w x w block holds the
//! unit lower triangle of L below its diagonal and D on its diagonal (what lies above the
//! diagonal is not read). The fill-reducing permutation is applied around the supernodal solve:
//! `x_perm[i] = b[fwd[i]]` before, `b[i] = x_perm[inv[i]]` after.
//!
//! The schedule. The parent of supernode s is the supernode of the first row of its pattern; the
//! rows of the patterns of a subtree lie in that subtree or in its ancestors (checked when the
//! schedule is built; where it does not hold, or the patterns are not sorted, faer's solve is
//! used). faer does not postorder the tree (it keeps a custom ordering such as nested dissection
//! as given), so a subtree is not a contiguous range of supernodes; but every descendant of s
//! comes before s and every ancestor after it, so the rows a set of sibling subtrees under p
//! updates outside itself are exactly those from `supernode_begin[p]` on. A task is either a run
//! of supernodes processed in increasing order (forward; decreasing backward), after an optional
//! task below it, or a split of a set of sibling subtrees into two groups of balanced work
//! (largest first, greedily) solved in parallel. Backward substitution reads only ancestors and
//! writes the task's own columns: no race. Forward substitution writes the ancestors: the left
//! group writes them where its enclosing task does, the right group into a buffer of its own
//! (indexed by depth: the columns of the ancestors of any supernode have distinct positions),
//! added after the join. Sets of subtrees with less than 1/64 of the work are run sequentially;
//! a group under a quarter of that is not split off but run by the task of its siblings.
//!
//! Inside a supernode the kernels stream L once: forward, y = [x_s; 0] of length w + m is
//! updated four columns at a time (y -= L[:, j..j+4] y[j..j+4] below the 4 x 4 triangle), then
//! y[..w] is x_s and y[w..] is scattered into the pattern's rows; backward, y = [x_s / d; x of the
//! pattern] and four columns at a time y[j..j+4] -= L[j+4.., j..j+4]^T y[j+4..] and the
//! triangle. faer's arithmetic is the same up to the order of the sums (agreement to round-off).
//! All workspaces (the permuted vector, every task's y and buffer) are allocated with the
//! schedule; a solve allocates nothing. The result does not depend on which thread runs what
//! (the buffers are added in a fixed order), only on the schedule.
//!
//! Measured 2026-11-24 (the ignored test `solve_pair` in cli/src/bench.rs: the bench tangent's
//! symmetric part, LdltGmres's ordering, one solve pair, the minimum of 10; other benchmarks
//! shared the 2 cores, the quietest of 4 runs):
//!
//! | n | unknowns | entries of L | faer, 1 / 2 threads s | ours sequential s | ours, 1 / 2 threads s | work / critical path |
//! |---|---|---|---|---|---|---|
//! | 100 | 60 400 (AMD) | 13.9 M | 0.0155 / 0.0156 | 0.0109 | 0.0111 / 0.0061 | 3.0 |
//! | 200 | 240 800 (ND) | 61.7 M | 0.0747 / 0.0766 | 0.0510 | 0.0524 / 0.0281 | 8.6 |
//!
//! One thread is a third faster than faer's solve (AVX2 kernels that read L once; faer reaches
//! about 13 GB/s, ours 19); two threads almost double that where the second core is free (35 GB/s
//! at n = 200), and gain little when another process holds it.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;
use faer::sparse::linalg::cholesky::{LdltRef, SymbolicCholesky, SymbolicCholeskyRaw};
use faer::{Conj, MatMut, Par};
use std::sync::Mutex;

const NONE: usize = usize::MAX;
/// Sets of subtrees with less than this share of the whole work are solved sequentially.
const SEQUENTIAL_SHARE: f64 = 1.0 / 64.0;
/// ... and never split below this work (entries of L).
const SEQUENTIAL_MIN_WORK: f64 = 16_384.0;
/// The lighter group of a split must have at least this part of the sequential cut-off.
const SPLIT_MIN_FRACTION: f64 = 0.25;

/// Pointer to a vector whose disjoint entries several tasks write.
#[derive(Clone, Copy)]
struct Shared(*mut f64);
// SAFETY: the schedule gives every task entries of its own (see the module doc).
unsafe impl Send for Shared {}
unsafe impl Sync for Shared {}

/// Where forward substitution sends its updates of a row: into x below `limit`, into
/// `buf[position]` from `limit` on.
#[derive(Clone, Copy)]
struct Target {
    limit: usize,
    buf: Shared,
}

enum Task {
    /// `below` first, then the supernodes `nodes` (increasing) with the workspace `y..y + len`;
    /// backward in the reverse order.
    Run { below: Option<Box<Task>>, nodes: Vec<usize>, y: usize, len: usize },
    /// Two groups of sibling subtrees under `anchor` (None: roots) in parallel, the right one's
    /// forward updates of the ancestors in the workspace `buf..buf + len`.
    Split { left: Box<Task>, right: Box<Task>, anchor: Option<usize>, buf: usize, len: usize },
}

/// The parallel schedule of the solves with the factors of one symbolic supernodal LDL^T (or,
/// for a simplicial factor or an unexpected structure, faer's solve).
pub struct SupernodalSolve {
    n: usize,
    len_val: usize,
    n_supernodes: usize,
    /// Supernodal elimination tree.
    parent: Vec<usize>,
    /// Position of every column in the ancestor buffers: the widths of its supernode's proper
    /// ancestors plus its rank in its supernode.
    position: Vec<u32>,
    /// None: faer's solve.
    root: Option<Task>,
    splits: usize,
    /// Rows of the largest supernode.
    max_rows: usize,
    /// The permuted vector (n), the sequential y (max_rows), then the tasks' y and buffers.
    workspace: Mutex<Vec<f64>>,
    /// faer's workspace, for the fallback.
    scratch: Mutex<Option<MemBuffer>>,
}

/// Geometry of supernode s: its first column, width, pattern and values.
#[inline]
fn supernode<'a>(sn: &'a SymbolicSupernodalCholesky<usize>, factor: &'a [f64], s: usize) -> (usize, usize, &'a [usize], &'a [f64]) {
    let begin = sn.supernode_begin()[s];
    let w = sn.supernode_end()[s] - begin;
    let rp = sn.col_ptr_for_row_idx();
    let vp = sn.col_ptr_for_val();
    (begin, w, &sn.row_idx()[rp[s]..rp[s + 1]], &factor[vp[s]..vp[s + 1]])
}

impl SupernodalSolve {
    /// The schedule for the factors of `symbolic`.
    pub fn new(symbolic: &SymbolicCholesky<usize>) -> Self {
        let n = symbolic.nrows();
        let mut this = SupernodalSolve {
            n,
            len_val: symbolic.len_val(),
            n_supernodes: 0,
            parent: Vec::new(),
            position: Vec::new(),
            root: None,
            splits: 0,
            max_rows: 0,
            workspace: Mutex::new(Vec::new()),
            scratch: Mutex::new(None),
        };
        if let SymbolicCholeskyRaw::Supernodal(sn) = symbolic.raw() {
            if let Some((root, workspace)) = this.schedule(sn) {
                this.root = Some(root);
                this.workspace = Mutex::new(vec![0.0; workspace]);
                return this;
            }
        }
        this
    }

    /// Whether the solve is the parallel one (a supernodal factor of the expected structure).
    pub fn is_parallel(&self) -> bool {
        self.root.is_some()
    }

    /// Number of parallel splits of the schedule.
    pub fn splits(&self) -> usize {
        self.splits
    }

    /// The work (entries of L) of the whole solve and of its critical path (the most that any
    /// number of threads must do one after the other): their ratio bounds the parallel speed-up.
    pub fn work_and_span(&self, symbolic: &SymbolicCholesky<usize>) -> (f64, f64) {
        fn walk(task: &Task, cost: &dyn Fn(usize) -> f64) -> (f64, f64) {
            match task {
                Task::Run { below, nodes, .. } => {
                    let own: f64 = nodes.iter().map(|&s| cost(s)).sum();
                    let (w, s) = below.as_ref().map_or((0.0, 0.0), |b| walk(b, cost));
                    (w + own, s + own)
                }
                Task::Split { left, right, .. } => {
                    let (l, r) = (walk(left, cost), walk(right, cost));
                    (l.0 + r.0, l.1.max(r.1))
                }
            }
        }
        let (Some(root), SymbolicCholeskyRaw::Supernodal(sn)) = (&self.root, symbolic.raw()) else { return (0.0, 0.0) };
        let vp = sn.col_ptr_for_val();
        walk(root, &|s| (vp[s + 1] - vp[s]) as f64)
    }

    /// Builds the tree, the positions and the tasks; returns the root task and the workspace
    /// length, None if the structure is not the expected one.
    fn schedule(&mut self, sn: &SymbolicSupernodalCholesky<usize>) -> Option<(Task, usize)> {
        let n = self.n;
        let ns = sn.n_supernodes();
        let (begin, end) = (sn.supernode_begin(), sn.supernode_end());
        let rp = sn.col_ptr_for_row_idx();
        let ri = sn.row_idx();
        let mut of = vec![0usize; n];
        for s in 0..ns {
            of[begin[s]..end[s]].iter_mut().for_each(|v| *v = s);
        }
        let mut parent = vec![NONE; ns];
        let mut rows = vec![0usize; ns];
        let mut work = vec![0.0f64; ns];
        for s in 0..ns {
            let pattern = &ri[rp[s]..rp[s + 1]];
            if pattern.windows(2).any(|p| p[0] >= p[1]) || pattern.first().is_some_and(|&i| i < end[s]) || pattern.last().is_some_and(|&i| i >= n) {
                return None;
            }
            if let Some(&i) = pattern.first() {
                parent[s] = of[i];
            }
            let w = end[s] - begin[s];
            rows[s] = w + pattern.len();
            work[s] = (rows[s] * w + pattern.len()) as f64;
        }
        // subtree sizes and work (children come before their parent)
        let mut size = vec![1usize; ns];
        let mut subtree = work.clone();
        for s in 0..ns {
            if parent[s] != NONE {
                size[parent[s]] += size[s];
                subtree[parent[s]] += subtree[s];
            }
        }
        // postorder numbers: subtree(s) = lo[s]..=post[s]; parents are numbered before children
        let mut lo = vec![0usize; ns];
        let mut cursor = vec![0usize; ns];
        let mut next = 0;
        for s in (0..ns).rev() {
            if parent[s] == NONE {
                lo[s] = next;
                next += size[s];
            } else {
                lo[s] = cursor[parent[s]];
                cursor[parent[s]] += size[s];
            }
            cursor[s] = lo[s];
        }
        let post = |s: usize| lo[s] + size[s] - 1;
        // every row of a pattern belongs to an ancestor
        for s in 0..ns {
            for &i in &ri[rp[s]..rp[s + 1]] {
                let a = of[i];
                if !(lo[a] <= post(s) && post(s) <= post(a)) {
                    return None;
                }
            }
        }
        // positions by depth (parents before children)
        let mut offset = vec![0usize; ns];
        for s in (0..ns).rev() {
            if parent[s] != NONE {
                offset[s] = offset[parent[s]] + end[parent[s]] - begin[parent[s]];
            }
        }
        let mut position = vec![0u32; n];
        for s in 0..ns {
            for (rank, p) in position[begin[s]..end[s]].iter_mut().enumerate() {
                *p = u32::try_from(offset[s] + rank).ok()?;
            }
        }
        // children lists
        let mut child_ptr = vec![0usize; ns + 1];
        for s in 0..ns {
            if parent[s] != NONE {
                child_ptr[parent[s] + 1] += 1;
            }
        }
        for s in 0..ns {
            child_ptr[s + 1] += child_ptr[s];
        }
        let mut children = vec![0usize; child_ptr[ns]];
        let mut fill = child_ptr.clone();
        for s in 0..ns {
            if parent[s] != NONE {
                children[fill[parent[s]]] = s;
                fill[parent[s]] += 1;
            }
        }
        let total: f64 = work.iter().sum();
        let cutoff = (total * SEQUENTIAL_SHARE).max(SEQUENTIAL_MIN_WORK);
        let max_rows = rows.iter().copied().max().unwrap_or(0);
        let mut builder = Builder {
            parent: &parent,
            children: &children,
            child_ptr: &child_ptr,
            subtree: &subtree,
            rows: &rows,
            offset: &offset,
            width: |p: usize| end[p] - begin[p],
            cutoff,
            split_min: cutoff * SPLIT_MIN_FRACTION,
            len: n + max_rows,
            splits: 0,
        };
        let roots: Vec<usize> = (0..ns).filter(|&s| parent[s] == NONE).collect();
        let root = builder.forest(roots);
        let len = builder.len;
        self.splits = builder.splits;
        self.n_supernodes = ns;
        self.parent = parent;
        self.position = position;
        self.max_rows = max_rows;
        Some((root, len))
    }

    /// x = A^-1 x with the LDL^T factor `factor` of `symbolic` (the symbolic factor this schedule
    /// was built for), the independent subtrees in parallel if `parallel`.
    pub fn solve_in_place(&self, symbolic: &SymbolicCholesky<usize>, factor: &[f64], x: &mut [f64], parallel: bool) {
        let n = self.n;
        assert!(x.len() == n && symbolic.nrows() == n && symbolic.len_val() == self.len_val && factor.len() == self.len_val, "a factor of another pattern");
        let (Some(root), SymbolicCholeskyRaw::Supernodal(sn)) = (&self.root, symbolic.raw()) else {
            return self.faer_solve(symbolic, factor, x, parallel);
        };
        assert!(sn.n_supernodes() == self.n_supernodes, "a factor of another pattern");
        let mut guard = self.workspace.lock().unwrap_or_else(|e| e.into_inner());
        let ws = guard.as_mut_slice();
        let perm = symbolic.perm();
        {
            let xp = &mut ws[..n];
            match perm {
                Some(p) => {
                    let fwd = p.arrays().0;
                    gather(xp, x, fwd, parallel);
                }
                None => xp.copy_from_slice(x),
            }
        }
        let base = ws.as_mut_ptr();
        let ctx = Context { sn, factor, position: &self.position, parent: &self.parent, n, x: Shared(base), ws: Shared(base) };
        let target = Target { limit: n, buf: Shared(std::ptr::null_mut()) };
        if parallel {
            ctx.forward_task(root, target);
            ctx.backward_task(root);
        } else {
            // SAFETY: one thread; the sequential y follows the permuted vector
            let y = unsafe { std::slice::from_raw_parts_mut(base.add(n), self.max_rows) };
            for s in 0..sn.n_supernodes() {
                unsafe { ctx.forward_node(s, ctx.x, y, target) };
            }
            for s in (0..sn.n_supernodes()).rev() {
                unsafe { ctx.backward_node(s, ctx.x, y) };
            }
        }
        let xp = &ws[..n];
        match perm {
            Some(p) => {
                let inv = p.arrays().1;
                gather(x, xp, inv, parallel);
            }
            None => x.copy_from_slice(xp),
        }
    }

    fn faer_solve(&self, symbolic: &SymbolicCholesky<usize>, factor: &[f64], x: &mut [f64], parallel: bool) {
        let par = if parallel { Par::rayon(0) } else { Par::Seq };
        let mut guard = self.scratch.lock().unwrap_or_else(|e| e.into_inner());
        let buffer = guard.get_or_insert_with(|| MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(1, par)));
        let n = x.len();
        LdltRef::new(symbolic, factor).solve_in_place_with_conj(Conj::No, MatMut::from_column_major_slice_mut(x, n, 1), par, MemStack::new(buffer));
    }
}

/// out[i] = v[index[i]], in parallel chunks if `parallel`.
fn gather(out: &mut [f64], v: &[f64], index: &[usize], parallel: bool) {
    const CHUNK: usize = 1 << 14;
    if parallel && out.len() > CHUNK {
        use rayon::prelude::*;
        out.par_chunks_mut(CHUNK).zip(index.par_chunks(CHUNK)).for_each(|(o, ix)| o.iter_mut().zip(ix).for_each(|(o, &i)| *o = v[i]));
    } else {
        out.iter_mut().zip(index).for_each(|(o, &i)| *o = v[i]);
    }
}

struct Builder<'a, W: Fn(usize) -> usize> {
    parent: &'a [usize],
    children: &'a [usize],
    child_ptr: &'a [usize],
    subtree: &'a [f64],
    rows: &'a [usize],
    offset: &'a [usize],
    width: W,
    cutoff: f64,
    split_min: f64,
    /// Workspace allocated so far.
    len: usize,
    splits: usize,
}

impl<W: Fn(usize) -> usize> Builder<'_, W> {
    fn children(&self, s: usize) -> &[usize] {
        &self.children[self.child_ptr[s]..self.child_ptr[s + 1]]
    }

    /// Appends the supernodes of the subtree of r.
    fn collect(&self, r: usize, out: &mut Vec<usize>) {
        let mut stack = vec![r];
        while let Some(s) = stack.pop() {
            out.push(s);
            stack.extend_from_slice(self.children(s));
        }
    }

    fn allocate(&mut self, len: usize) -> usize {
        self.len += len;
        self.len - len
    }

    /// The task of a set of sibling subtrees.
    fn forest(&mut self, mut roots: Vec<usize>) -> Task {
        let mut nodes = Vec::new();
        let below = loop {
            let total: f64 = roots.iter().map(|&r| self.subtree[r]).sum();
            if roots.is_empty() {
                break None;
            }
            if total < self.cutoff {
                for &r in &roots {
                    self.collect(r, &mut nodes);
                }
                break None;
            }
            if roots.len() == 1 {
                nodes.push(roots[0]);
                roots = self.children(roots[0]).to_vec();
                continue;
            }
            // two groups, the heaviest subtree first into the lighter group
            roots.sort_by(|&a, &b| self.subtree[b].total_cmp(&self.subtree[a]));
            let (mut a, mut b) = (Vec::new(), Vec::new());
            let (mut wa, mut wb) = (0.0, 0.0);
            for &r in &roots {
                if wa <= wb {
                    a.push(r);
                    wa += self.subtree[r];
                } else {
                    b.push(r);
                    wb += self.subtree[r];
                }
            }
            let (a, b, wb) = if wa >= wb { (a, b, wb) } else { (b, a, wa) };
            if wb < self.split_min {
                // not worth a task: run it before the chain above
                for &r in &b {
                    self.collect(r, &mut nodes);
                }
                roots = a;
                continue;
            }
            let anchor = match self.parent[roots[0]] {
                NONE => None,
                p => Some(p),
            };
            let left = Box::new(self.forest(a));
            let right = Box::new(self.forest(b));
            let len = anchor.map_or(0, |p| self.offset[p] + (self.width)(p));
            let buf = self.allocate(len);
            self.splits += 1;
            break Some(Box::new(Task::Split { left, right, anchor, buf, len }));
        };
        nodes.sort_unstable();
        match below {
            Some(task) if nodes.is_empty() => *task,
            below => {
                let len = nodes.iter().map(|&s| self.rows[s]).max().unwrap_or(0);
                let y = self.allocate(len);
                Task::Run { below, nodes, y, len }
            }
        }
    }
}

/// What the tasks of one solve share.
struct Context<'a> {
    sn: &'a SymbolicSupernodalCholesky<usize>,
    factor: &'a [f64],
    position: &'a [u32],
    parent: &'a [usize],
    n: usize,
    /// The permuted vector (the first n entries of the workspace).
    x: Shared,
    ws: Shared,
}

// SAFETY (all of Context's unsafe blocks): the workspace regions of the tasks are disjoint (the
// builder allocates them one after the other past the permuted vector); a task writes the columns
// of its own supernodes, and forward the rows of their ancestors either in x (where no task
// running at the same time writes them: those rows belong to the enclosing split's subtrees, not
// to the other group's) or in its own buffer.
impl Context<'_> {
    fn forward_task(&self, task: &Task, target: Target) {
        match task {
            Task::Run { below, nodes, y, len } => {
                if let Some(b) = below {
                    self.forward_task(b, target);
                }
                let y = unsafe { std::slice::from_raw_parts_mut(self.ws.0.add(*y), *len) };
                for &s in nodes {
                    unsafe { self.forward_node(s, self.x, y, target) };
                }
            }
            Task::Split { left, right, anchor, buf, len } => {
                let own = Shared(unsafe { self.ws.0.add(*buf) });
                let limit = anchor.map_or(self.n, |p| self.sn.supernode_begin()[p]);
                rayon::join(
                    || self.forward_task(left, target),
                    || {
                        unsafe { std::slice::from_raw_parts_mut(own.0, *len) }.fill(0.0);
                        self.forward_task(right, Target { limit, buf: own });
                    },
                );
                // the right group's updates of the ancestors, where the left group's went
                let mut a = anchor.unwrap_or(NONE);
                while a != NONE {
                    for i in self.sn.supernode_begin()[a]..self.sn.supernode_end()[a] {
                        let k = self.position[i] as usize;
                        unsafe {
                            let v = *own.0.add(k);
                            if i < target.limit {
                                *self.x.0.add(i) += v;
                            } else {
                                *target.buf.0.add(k) += v;
                            }
                        }
                    }
                    a = self.parent[a];
                }
            }
        }
    }

    fn backward_task(&self, task: &Task) {
        match task {
            Task::Run { below, nodes, y, len } => {
                let y = unsafe { std::slice::from_raw_parts_mut(self.ws.0.add(*y), *len) };
                for &s in nodes.iter().rev() {
                    unsafe { self.backward_node(s, self.x, y) };
                }
                if let Some(b) = below {
                    self.backward_task(b);
                }
            }
            Task::Split { left, right, .. } => {
                rayon::join(|| self.backward_task(left), || self.backward_task(right));
            }
        }
    }

    /// Forward substitution with supernode s: x_s = L_ss^-1 x_s, x_p -= L_ps x_s.
    ///
    /// # Safety
    /// x must hold n entries, the task must own supernode s and the updates `target` directs.
    #[inline]
    unsafe fn forward_node(&self, s: usize, x: Shared, y: &mut [f64], target: Target) {
        let (begin, w, pattern, l) = supernode(self.sn, self.factor, s);
        let ld = w + pattern.len();
        let y = &mut y[..ld];
        let xs = std::slice::from_raw_parts_mut(x.0.add(begin), w);
        y[..w].copy_from_slice(xs);
        y[w..].fill(0.0);
        lower_solve(l, ld, w, y);
        xs.copy_from_slice(&y[..w]);
        let split = if target.limit >= self.n { pattern.len() } else { pattern.partition_point(|&i| i < target.limit) };
        let (update, inside, outside) = (&y[w..], &pattern[..split], &pattern[split..]);
        for (&i, v) in inside.iter().zip(update) {
            *x.0.add(i) += v;
        }
        for (&i, v) in outside.iter().zip(&update[split..]) {
            *target.buf.0.add(self.position[i] as usize) += v;
        }
    }

    /// Diagonal and backward substitution with supernode s: x_s = L_ss^-T (D_s^-1 x_s - L_ps^T x_p).
    ///
    /// # Safety
    /// x must hold n entries, the task must own supernode s, and its ancestors must be solved.
    #[inline]
    unsafe fn backward_node(&self, s: usize, x: Shared, y: &mut [f64]) {
        let (begin, w, pattern, l) = supernode(self.sn, self.factor, s);
        let ld = w + pattern.len();
        let y = &mut y[..ld];
        for (v, &i) in y[w..].iter_mut().zip(pattern) {
            *v = *x.0.add(i);
        }
        let xs = std::slice::from_raw_parts_mut(x.0.add(begin), w);
        for (j, (v, xj)) in y[..w].iter_mut().zip(xs.iter()).enumerate() {
            // as faer: x times the reciprocal of d
            *v = xj * l[j * ld + j].recip();
        }
        upper_solve(l, ld, w, y);
        xs.copy_from_slice(&y[..w]);
    }
}

/// With L the (ld x w) column-major unit lower trapezoid `l`: y[..w] = L_top^-1 y[..w], then
/// y[w..] -= L_bottom y[..w]. Four columns at a time, L read once.
#[inline]
fn lower_solve(l: &[f64], ld: usize, w: usize, y: &mut [f64]) {
    let mut j = 0;
    while j + 4 <= w {
        let c = &l[j * ld..(j + 4) * ld];
        let (c0, rest) = c.split_at(ld);
        let (c1, rest) = rest.split_at(ld);
        let (c2, c3) = rest.split_at(ld);
        y[j + 1] -= c0[j + 1] * y[j];
        y[j + 2] -= c0[j + 2] * y[j] + c1[j + 2] * y[j + 1];
        y[j + 3] -= c0[j + 3] * y[j] + c1[j + 3] * y[j + 1] + c2[j + 3] * y[j + 2];
        let a = [y[j], y[j + 1], y[j + 2], y[j + 3]];
        let r = j + 4;
        axpy4(&c0[r..], &c1[r..], &c2[r..], &c3[r..], a, &mut y[r..]);
        j += 4;
    }
    while j < w {
        let c = &l[j * ld + j + 1..(j + 1) * ld];
        let a = y[j];
        axpy(c, a, &mut y[j + 1..]);
        j += 1;
    }
}

/// y -= c0 a0 + c1 a1 + c2 a2 + c3 a3.
#[inline]
fn axpy4(c0: &[f64], c1: &[f64], c2: &[f64], c3: &[f64], a: [f64; 4], y: &mut [f64]) {
    let n = y.len();
    let (c0, c1, c2, c3) = (&c0[..n], &c1[..n], &c2[..n], &c3[..n]);
    #[cfg(target_arch = "x86_64")]
    if simd::available() {
        // SAFETY: the CPU has AVX2 and FMA; all slices hold n entries
        return unsafe { simd::axpy4(c0.as_ptr(), c1.as_ptr(), c2.as_ptr(), c3.as_ptr(), a, y.as_mut_ptr(), n) };
    }
    for r in 0..n {
        y[r] -= c0[r] * a[0] + c1[r] * a[1] + c2[r] * a[2] + c3[r] * a[3];
    }
}

/// y -= c a.
#[inline]
fn axpy(c: &[f64], a: f64, y: &mut [f64]) {
    let n = c.len();
    let y = &mut y[..n];
    #[cfg(target_arch = "x86_64")]
    if simd::available() {
        // SAFETY: the CPU has AVX2 and FMA; both slices hold n entries
        return unsafe { simd::axpy1(c.as_ptr(), a, y.as_mut_ptr(), n) };
    }
    for (v, lv) in y.iter_mut().zip(c) {
        *v -= lv * a;
    }
}

/// With L as in [`lower_solve`]: y[j] -= sum_{r > j} L[r, j] y[r] for j = w - 1 down to 0, i.e.
/// y[..w] = L_top^-T (y[..w] - L_bottom^T y[w..]). Four columns at a time.
#[inline]
fn upper_solve(l: &[f64], ld: usize, w: usize, y: &mut [f64]) {
    let mut j = w;
    for _ in 0..w % 4 {
        j -= 1;
        let c = &l[j * ld + j + 1..(j + 1) * ld];
        y[j] -= dot(c, &y[j + 1..]);
    }
    while j >= 4 {
        j -= 4;
        let c = &l[j * ld..(j + 4) * ld];
        let (c0, rest) = c.split_at(ld);
        let (c1, rest) = rest.split_at(ld);
        let (c2, c3) = rest.split_at(ld);
        let r = j + 4;
        let s = dot4(&c0[r..], &c1[r..], &c2[r..], &c3[r..], &y[r..]);
        y[j + 3] -= s[3];
        y[j + 2] -= s[2] + c2[j + 3] * y[j + 3];
        y[j + 1] -= s[1] + c1[j + 2] * y[j + 2] + c1[j + 3] * y[j + 3];
        y[j] -= s[0] + c0[j + 1] * y[j + 1] + c0[j + 2] * y[j + 2] + c0[j + 3] * y[j + 3];
    }
}

/// sum c[r] y[r].
#[inline]
fn dot(c: &[f64], y: &[f64]) -> f64 {
    let n = c.len();
    let y = &y[..n];
    #[cfg(target_arch = "x86_64")]
    if simd::available() {
        // SAFETY: the CPU has AVX2 and FMA; both slices hold n entries
        return unsafe { simd::dot4(c.as_ptr(), c.as_ptr(), c.as_ptr(), c.as_ptr(), y.as_ptr(), n, 1)[0] };
    }
    let mut acc = [0.0f64; 4];
    let (cc, yc) = (c.chunks_exact(4), y.chunks_exact(4));
    let (cr, yr) = (cc.remainder(), yc.remainder());
    for (c, y) in cc.zip(yc) {
        for k in 0..4 {
            acc[k] += c[k] * y[k];
        }
    }
    let mut sum = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for (c, y) in cr.iter().zip(yr) {
        sum += c * y;
    }
    sum
}

/// The four sums c_k[r] y[r].
#[inline]
fn dot4(c0: &[f64], c1: &[f64], c2: &[f64], c3: &[f64], y: &[f64]) -> [f64; 4] {
    let n = y.len();
    let (c0, c1, c2, c3) = (&c0[..n], &c1[..n], &c2[..n], &c3[..n]);
    #[cfg(target_arch = "x86_64")]
    if simd::available() {
        // SAFETY: the CPU has AVX2 and FMA; all slices hold n entries
        return unsafe { simd::dot4(c0.as_ptr(), c1.as_ptr(), c2.as_ptr(), c3.as_ptr(), y.as_ptr(), n, 4) };
    }
    let mut s = [0.0f64; 4];
    for r in 0..n {
        let v = y[r];
        s[0] += c0[r] * v;
        s[1] += c1[r] * v;
        s[2] += c2[r] * v;
        s[3] += c3[r] * v;
    }
    s
}

/// AVX2 and FMA kernels (faer's own dense kernels dispatch to these instructions at run time
/// too).
#[cfg(target_arch = "x86_64")]
mod simd {
    use std::arch::x86_64::*;

    #[inline]
    pub fn available() -> bool {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }

    /// y[r] -= c0[r] a0 + c1[r] a1 + c2[r] a2 + c3[r] a3 for r < n.
    ///
    /// # Safety
    /// AVX2 and FMA; every pointer valid for n entries.
    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn axpy4(c0: *const f64, c1: *const f64, c2: *const f64, c3: *const f64, a: [f64; 4], y: *mut f64, n: usize) {
        let (a0, a1, a2, a3) = (_mm256_set1_pd(a[0]), _mm256_set1_pd(a[1]), _mm256_set1_pd(a[2]), _mm256_set1_pd(a[3]));
        let mut r = 0;
        while r + 4 <= n {
            let mut v = _mm256_loadu_pd(y.add(r));
            v = _mm256_fnmadd_pd(_mm256_loadu_pd(c0.add(r)), a0, v);
            v = _mm256_fnmadd_pd(_mm256_loadu_pd(c1.add(r)), a1, v);
            v = _mm256_fnmadd_pd(_mm256_loadu_pd(c2.add(r)), a2, v);
            v = _mm256_fnmadd_pd(_mm256_loadu_pd(c3.add(r)), a3, v);
            _mm256_storeu_pd(y.add(r), v);
            r += 4;
        }
        while r < n {
            *y.add(r) -= *c0.add(r) * a[0] + *c1.add(r) * a[1] + *c2.add(r) * a[2] + *c3.add(r) * a[3];
            r += 1;
        }
    }

    /// y[r] -= c[r] a for r < n.
    ///
    /// # Safety
    /// AVX2 and FMA; both pointers valid for n entries.
    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn axpy1(c: *const f64, a: f64, y: *mut f64, n: usize) {
        let av = _mm256_set1_pd(a);
        let mut r = 0;
        while r + 4 <= n {
            _mm256_storeu_pd(y.add(r), _mm256_fnmadd_pd(_mm256_loadu_pd(c.add(r)), av, _mm256_loadu_pd(y.add(r))));
            r += 4;
        }
        while r < n {
            *y.add(r) -= *c.add(r) * a;
            r += 1;
        }
    }

    /// The sums c_k[r] y[r] over r < n for the first `columns` (1 or 4) of c0..c3.
    ///
    /// # Safety
    /// AVX2 and FMA; every pointer valid for n entries.
    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn dot4(c0: *const f64, c1: *const f64, c2: *const f64, c3: *const f64, y: *const f64, n: usize, columns: usize) -> [f64; 4] {
        let hsum = |v: __m256d| {
            let lo = _mm256_castpd256_pd128(v);
            let hi = _mm256_extractf128_pd(v, 1);
            let s = _mm_add_pd(lo, hi);
            _mm_cvtsd_f64(_mm_add_pd(s, _mm_unpackhi_pd(s, s)))
        };
        if columns == 1 {
            // two chains of four lanes
            let (mut s0, mut s1) = (_mm256_setzero_pd(), _mm256_setzero_pd());
            let mut r = 0;
            while r + 8 <= n {
                s0 = _mm256_fmadd_pd(_mm256_loadu_pd(c0.add(r)), _mm256_loadu_pd(y.add(r)), s0);
                s1 = _mm256_fmadd_pd(_mm256_loadu_pd(c0.add(r + 4)), _mm256_loadu_pd(y.add(r + 4)), s1);
                r += 8;
            }
            let mut s = hsum(_mm256_add_pd(s0, s1));
            while r < n {
                s += *c0.add(r) * *y.add(r);
                r += 1;
            }
            return [s, 0.0, 0.0, 0.0];
        }
        // eight chains: two per column
        let z = _mm256_setzero_pd();
        let (mut a0, mut a1, mut a2, mut a3) = (z, z, z, z);
        let (mut b0, mut b1, mut b2, mut b3) = (z, z, z, z);
        let mut r = 0;
        while r + 8 <= n {
            let v = _mm256_loadu_pd(y.add(r));
            let w = _mm256_loadu_pd(y.add(r + 4));
            a0 = _mm256_fmadd_pd(_mm256_loadu_pd(c0.add(r)), v, a0);
            a1 = _mm256_fmadd_pd(_mm256_loadu_pd(c1.add(r)), v, a1);
            a2 = _mm256_fmadd_pd(_mm256_loadu_pd(c2.add(r)), v, a2);
            a3 = _mm256_fmadd_pd(_mm256_loadu_pd(c3.add(r)), v, a3);
            b0 = _mm256_fmadd_pd(_mm256_loadu_pd(c0.add(r + 4)), w, b0);
            b1 = _mm256_fmadd_pd(_mm256_loadu_pd(c1.add(r + 4)), w, b1);
            b2 = _mm256_fmadd_pd(_mm256_loadu_pd(c2.add(r + 4)), w, b2);
            b3 = _mm256_fmadd_pd(_mm256_loadu_pd(c3.add(r + 4)), w, b3);
            r += 8;
        }
        let mut s = [hsum(_mm256_add_pd(a0, b0)), hsum(_mm256_add_pd(a1, b1)), hsum(_mm256_add_pd(a2, b2)), hsum(_mm256_add_pd(a3, b3))];
        while r < n {
            let v = *y.add(r);
            s[0] += *c0.add(r) * v;
            s[1] += *c1.add(r) * v;
            s[2] += *c2.add(r) * v;
            s[3] += *c3.add(r) * v;
            r += 1;
        }
        s
    }
}
#[cfg(test)]
mod tests {
    use super::*;
    use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
    use faer::perm::PermRef;
    use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, CholeskySymbolicParams, SymmetricOrdering};
    use faer::sparse::{SparseColMat, Triplet};
    use faer::Side;

    /// xorshift, in [-1, 1).
    struct Random(u64);
    impl Random {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        }
    }

    /// A k x k grid of nodes with `dofs` unknowns each, every node coupled to its 8 neighbours by
    /// random blocks; symmetric, strictly diagonally dominant, the last unknown of every node
    /// with a negative diagonal if `indefinite` (D then has negative entries).
    fn grid(k: usize, dofs: usize, indefinite: bool, seed: u64) -> SparseColMat<usize, f64> {
        let mut rng = Random(seed);
        let n = k * k * dofs;
        let mut t = Vec::new();
        let mut row_sum = vec![0.0f64; n];
        for (x, y) in (0..k).flat_map(|x| (0..k).map(move |y| (x, y))) {
            let a = x * k + y;
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1), (1, usize::MAX)] {
                let (x2, y2) = (x + dx, y.wrapping_add(dy));
                if x2 >= k || y2 >= k {
                    continue;
                }
                let b = x2 * k + y2;
                for p in 0..dofs {
                    for q in 0..dofs {
                        let (i, j) = (a * dofs + p, b * dofs + q);
                        if i == j || (a == b && j < i) {
                            continue;
                        }
                        let v = rng.next();
                        t.push(Triplet::new(i, j, v));
                        t.push(Triplet::new(j, i, v));
                        row_sum[i] += v.abs();
                        row_sum[j] += v.abs();
                    }
                }
            }
        }
        for (i, sum) in row_sum.iter().enumerate() {
            let d = sum + 0.5 + rng.next().abs();
            t.push(Triplet::new(i, i, if indefinite && i % dofs == dofs - 1 { -d } else { d }));
        }
        SparseColMat::try_new_from_triplets(n, n, &t).unwrap()
    }

    fn factorise(a: &SparseColMat<usize, f64>, nested: bool) -> (SymbolicCholesky<usize>, Vec<f64>) {
        let n = a.nrows();
        let (cp, ri) = (a.symbolic().col_ptr(), a.symbolic().row_idx());
        let perm = nested.then(|| crate::linalg::ordering::nested_dissection(cp, ri).unwrap());
        let inv = perm.as_deref().map(crate::linalg::ordering::inverse);
        let ord = match (&perm, &inv) {
            (Some(p), Some(i)) => SymmetricOrdering::Custom(PermRef::new_checked(p, i, n)),
            _ => SymmetricOrdering::Amd,
        };
        let sym = factorize_symbolic_cholesky(a.symbolic(), Side::Lower, ord, CholeskySymbolicParams::default()).unwrap();
        let mut factor = vec![0.0; sym.len_val()];
        let mut buf = MemBuffer::new(sym.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()));
        sym.factorize_numeric_ldlt(&mut factor, a.as_ref(), Side::Lower, LdltRegularization::default(), Par::Seq, MemStack::new(&mut buf), Default::default())
            .unwrap();
        (sym, factor)
    }

    fn faer_solve(sym: &SymbolicCholesky<usize>, factor: &[f64], b: &[f64]) -> Vec<f64> {
        let mut x = b.to_vec();
        let n = x.len();
        let mut buf = MemBuffer::new(sym.solve_in_place_scratch::<f64>(1, Par::Seq));
        LdltRef::new(sym, factor).solve_in_place_with_conj(Conj::No, MatMut::from_column_major_slice_mut(&mut x, n, 1), Par::Seq, MemStack::new(&mut buf));
        x
    }

    fn relative_difference(x: &[f64], y: &[f64]) -> f64 {
        let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        x.iter().zip(y).fold(0.0f64, |m, (a, b)| m.max((a - b).abs())) / scale
    }

    /// min over i of d_i (the diagonal of every supernode's top block).
    fn smallest_pivot(sym: &SymbolicCholesky<usize>, factor: &[f64]) -> f64 {
        let SymbolicCholeskyRaw::Supernodal(sn) = sym.raw() else { panic!("simplicial") };
        (0..sn.n_supernodes())
            .flat_map(|s| {
                let (_, w, pattern, l) = supernode(sn, factor, s);
                let ld = w + pattern.len();
                (0..w).map(move |j| l[j * ld + j])
            })
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn agrees_with_faer_on_supernodal_factors() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(3).build().unwrap();
        for (k, dofs, indefinite, nested) in [(40, 3, false, false), (40, 3, true, true), (60, 2, true, false), (30, 6, false, true)] {
            let a = grid(k, dofs, indefinite, 7 + k as u64);
            let n = a.nrows();
            let (sym, factor) = factorise(&a, nested);
            assert!(matches!(sym.raw(), SymbolicCholeskyRaw::Supernodal(_)), "{k} x {k} x {dofs}: simplicial");
            assert_eq!(smallest_pivot(&sym, &factor) < 0.0, indefinite);
            let solver = SupernodalSolve::new(&sym);
            assert!(solver.is_parallel(), "{k} x {k} x {dofs}: no schedule");
            assert!(solver.splits() >= 4, "{} splits", solver.splits());
            let mut rng = Random(3);
            let b: Vec<f64> = (0..n).map(|_| rng.next()).collect();
            let expected = faer_solve(&sym, &factor, &b);
            let mut seq = b.clone();
            solver.solve_in_place(&sym, &factor, &mut seq, false);
            let mut par = b.clone();
            pool.install(|| solver.solve_in_place(&sym, &factor, &mut par, true));
            let (e_seq, e_par, e_between) = (relative_difference(&seq, &expected), relative_difference(&par, &expected), relative_difference(&par, &seq));
            assert!(e_seq <= 1e-12 && e_par <= 1e-12 && e_between <= 1e-12, "{k} x {k} x {dofs}, indefinite {indefinite}, ND {nested}: {e_seq:e} {e_par:e} {e_between:e}");
            // and it solves A x = b
            let mut r = b.clone();
            let (cp, ri, v) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
            for j in 0..n {
                for p in cp[j]..cp[j + 1] {
                    r[ri[p]] -= v[p] * par[j];
                }
            }
            assert!(r.iter().fold(0.0f64, |m, v| m.max(v.abs())) < 1e-10);
            // again: the workspace is reused (the buffers are cleared before use)
            let mut again = b.clone();
            pool.install(|| solver.solve_in_place(&sym, &factor, &mut again, true));
            assert!(relative_difference(&again, &par) <= 1e-14);
        }
    }

    /// b^T A^-1 c from the forward columns of sparse b and c equals the same from a whole solve,
    /// for vectors of one unknown and of several nodes apart, on definite and indefinite factors,
    /// AMD and nested dissection; the scratch is clean after each column.
    #[test]
    fn forward_columns_give_the_compliance_of_a_whole_solve() {
        for (k, dofs, indefinite, nested) in [(40, 3, false, false), (40, 3, true, true), (30, 6, false, true)] {
            let a = grid(k, dofs, indefinite, 11 + k as u64);
            let n = a.nrows();
            let (sym, factor) = factorise(&a, nested);
            let mut forward = SparseForward::new(&sym).expect("a supernodal factor");
            let mut rng = Random(5);
            // sparse vectors: a node's unknowns with random weights, at spread nodes, one of them
            // of a single unknown and one over two nodes
            let mut vectors: Vec<Vec<(usize, f64)>> = (0..6)
                .map(|i| {
                    let node = (i * 7919 + 13) % (k * k);
                    (0..dofs).map(|p| (node * dofs + p, rng.next())).collect()
                })
                .collect();
            vectors.push(vec![(n / 2, 1.0)]);
            vectors.push(vec![(3, 0.5), (n - 2, -1.5)]);
            let columns: Vec<ForwardColumn> = vectors.iter().map(|b| forward.column(&sym, &factor, b)).collect();
            assert!(forward.work.iter().all(|&x| x == 0.0), "the scratch is left clean");
            let dense = |b: &[(usize, f64)]| {
                let mut v = vec![0.0; n];
                b.iter().for_each(|&(i, x)| v[i] += x);
                v
            };
            for (i, bi) in vectors.iter().enumerate() {
                let x = faer_solve(&sym, &factor, &dense(bi));
                for (j, bj) in vectors.iter().enumerate() {
                    let expected: f64 = bj.iter().map(|&(e, c)| c * x[e]).sum();
                    let got = columns[j].dot(&columns[i]);
                    assert!((got - expected).abs() <= 1e-11 * expected.abs().max(1.0), "{k} x {k} x {dofs} ({indefinite}, {nested}): b{j}^T A^-1 b{i} = {got} against {expected}");
                }
            }
            // a path is much shorter than the factor: only the ancestors' rows are computed
            let longest = columns.iter().map(|c| c.y.len()).max().unwrap();
            assert!(longest < n / 4, "{longest} of {n} rows on a path");
        }
    }

    #[test]
    fn a_simplicial_factor_falls_back_to_faer() {
        let mut t = Vec::new();
        for i in 0..300 {
            t.push(Triplet::new(i, i, 2.5));
            if i + 1 < 300 {
                t.push(Triplet::new(i, i + 1, -1.0));
                t.push(Triplet::new(i + 1, i, -1.0));
            }
        }
        let a = SparseColMat::try_new_from_triplets(300, 300, &t).unwrap();
        let (sym, factor) = factorise(&a, false);
        assert!(matches!(sym.raw(), SymbolicCholeskyRaw::Simplicial(_)));
        let solver = SupernodalSolve::new(&sym);
        assert!(!solver.is_parallel());
        let b: Vec<f64> = (0..300).map(|i| (i as f64 * 0.37).sin()).collect();
        let expected = faer_solve(&sym, &factor, &b);
        for parallel in [false, true] {
            let mut x = b.clone();
            solver.solve_in_place(&sym, &factor, &mut x, parallel);
            assert_eq!(x, expected);
        }
    }
}

/// The forward half y = L^-1 Pi b of a solve with a supernodal factor A = Pi^T L D L^T Pi, for a
/// sparse b: y is zero outside the supernodes on the paths from b's supernodes to the root, and
/// only those are computed (a few separators of the nested dissection instead of the whole
/// factor). Two such columns give b^T A^-1 c = y_b^T D^-1 y_c ([`ForwardColumn::dot`]): the
/// compliance between contact points without a whole solve per point.
pub struct ForwardColumn {
    /// The supernodes of the path, increasing.
    nodes: Vec<u32>,
    /// Where each node's segment starts in `y` (one past the last: `y.len()`).
    start: Vec<u32>,
    /// y on the path's columns, and y / d.
    y: Vec<f64>,
    yd: Vec<f64>,
    /// A bordered matrix's terms (`BorderedSolver`): b's (b1 . Y - b2) and (A21 A11^-1 b1 - b2),
    /// and S^-1, so that b^T K^-1 c = y_b^T D^-1 y_c + left_b^T S^-1 right_c.
    border: Option<(Vec<f64>, Vec<f64>, std::sync::Arc<nalgebra::DMatrix<f64>>)>,
}

impl ForwardColumn {
    /// b^T A^-1 c for the vectors b and c of `self` and `other` (A symmetric): the sum over
    /// the supernodes both paths hold (the common ancestors).
    pub fn dot(&self, other: &ForwardColumn) -> f64 {
        let mut sum = match (&self.border, &other.border) {
            (Some((left, _, inverse)), Some((_, right, _))) => (0..left.len()).map(|k| left[k] * (0..right.len()).map(|l| inverse[(k, l)] * right[l]).sum::<f64>()).sum(),
            _ => 0.0,
        };
        let (mut i, mut j) = (0, 0);
        while i < self.nodes.len() && j < other.nodes.len() {
            match self.nodes[i].cmp(&other.nodes[j]) {
                std::cmp::Ordering::Less => i += 1,
                std::cmp::Ordering::Greater => j += 1,
                std::cmp::Ordering::Equal => {
                    let a = &self.y[self.start[i] as usize..self.segment_end(i)];
                    let b = &other.yd[other.start[j] as usize..other.segment_end(j)];
                    sum += a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
                    i += 1;
                    j += 1;
                }
            }
        }
        sum
    }

    /// The column of a bordered matrix's vector: its leading part's forward column with the
    /// border's terms (see `border`).
    pub fn with_border(mut self, left: Vec<f64>, right: Vec<f64>, inverse: std::sync::Arc<nalgebra::DMatrix<f64>>) -> Self {
        self.border = Some((left, right, inverse));
        self
    }

    fn segment_end(&self, i: usize) -> usize {
        self.start.get(i + 1).map_or(self.y.len(), |&s| s as usize)
    }
}

/// Computes [`ForwardColumn`]s with the factors of one symbolic supernodal LDL^T.
pub struct SparseForward {
    /// The supernode of every (permuted) column.
    of: Vec<u32>,
    /// The parent of every supernode (u32::MAX: a root).
    parent: Vec<u32>,
    /// Dense scratch of the matrix's size, zero between calls.
    work: Vec<f64>,
    y: Vec<f64>,
}

impl SparseForward {
    /// None for a simplicial factor.
    pub fn new(symbolic: &SymbolicCholesky<usize>) -> Option<Self> {
        let SymbolicCholeskyRaw::Supernodal(sn) = symbolic.raw() else { return None };
        let (n, ns) = (symbolic.nrows(), sn.n_supernodes());
        let (begin, end) = (sn.supernode_begin(), sn.supernode_end());
        let mut of = vec![0u32; n];
        for s in 0..ns {
            of[begin[s]..end[s]].iter_mut().for_each(|v| *v = s as u32);
        }
        let rp = sn.col_ptr_for_row_idx();
        let ri = sn.row_idx();
        let parent = (0..ns).map(|s| ri[rp[s]..rp[s + 1]].first().map_or(u32::MAX, |&i| of[i])).collect();
        let max_rows = (0..ns).map(|s| end[s] - begin[s] + rp[s + 1] - rp[s]).max().unwrap_or(0);
        Some(SparseForward { of, parent, work: vec![0.0; n], y: vec![0.0; max_rows] })
    }

    /// The forward column of b (pairs of an unpermuted index and a value) with the factor
    /// `factor` of `symbolic`.
    pub fn column(&mut self, symbolic: &SymbolicCholesky<usize>, factor: &[f64], b: &[(usize, f64)]) -> ForwardColumn {
        let SymbolicCholeskyRaw::Supernodal(sn) = symbolic.raw() else { unreachable!("SparseForward is built for supernodal factors only") };
        let inv = symbolic.perm().map(|p| p.arrays().1);
        let mut nodes: Vec<u32> = Vec::new();
        for &(e, v) in b {
            let p = inv.map_or(e, |inv| inv[e]);
            self.work[p] += v;
            let mut s = self.of[p];
            // the path to the root, until it meets one already taken
            while s != u32::MAX && !nodes.contains(&s) {
                nodes.push(s);
                s = self.parent[s as usize];
            }
        }
        nodes.sort_unstable();
        let mut start = Vec::with_capacity(nodes.len());
        let mut y = Vec::new();
        let mut yd = Vec::new();
        for &s in &nodes {
            let (begin, w, pattern, l) = supernode(sn, factor, s as usize);
            let ld = w + pattern.len();
            let t = &mut self.y[..ld];
            t[..w].copy_from_slice(&self.work[begin..begin + w]);
            t[w..].fill(0.0);
            lower_solve(l, ld, w, t);
            for (&i, v) in pattern.iter().zip(&t[w..]) {
                self.work[i] += v;
            }
            start.push(y.len() as u32);
            for j in 0..w {
                y.push(t[j]);
                yd.push(t[j] * l[j * ld + j].recip());
            }
            self.work[begin..begin + w].fill(0.0);
        }
        ForwardColumn { nodes, start, y, yd, border: None }
    }
}
