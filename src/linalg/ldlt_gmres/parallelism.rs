//! The threads of faer's numeric LDL^T, chosen by timing the first two factorisations of a
//! pattern.

use faer::Par;

/// The parallelism of faer's numeric LDL^T, chosen by measurement, not assumed. With a parallel setting, the first numeric
/// factorisation of a pattern runs on the threads and the second on one; every later one the way
/// that was faster. Measured on the 2-core machine with `stamp bench` (2026-11-24): faer's
/// parallel supernodal factorisation spends its time in scheduling (a third of the samples in
/// the kernel's sched_yield and task switches), one factorisation 0.95 s on two threads against
/// 0.65 s on one at n = 200 (240 800 unknowns), 5.2 s either way at n = 400; on a machine with
/// more cores the threads may win, and then they are kept.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct FactorParallelism {
    /// Seconds of the factorisation on the threads and on one, once measured.
    threads: Option<f64>,
    one: Option<f64>,
    /// The setting of the factorisation under way.
    trying: Option<Par>,
}

impl FactorParallelism {
    /// The setting for the next factorisation, given the solver's (`par`), without choosing it.
    pub(super) fn next(&self, par: Par) -> Par {
        match (par, self.threads, self.threads_won()) {
            (Par::Seq, _, _) | (_, Some(_), None | Some(false)) => Par::Seq,
            _ => par,
        }
    }

    /// The setting for the next factorisation, given the solver's (`par`).
    pub(super) fn choose(&mut self, par: Par) -> Par {
        let chosen = self.next(par);
        self.trying = Some(chosen);
        chosen
    }

    /// The seconds of the factorisation made with the last [`FactorParallelism::choose`].
    pub(super) fn record(&mut self, seconds: f64) {
        match self.trying.take() {
            Some(Par::Seq) if self.threads.is_some() && self.one.is_none() => self.one = Some(seconds),
            Some(Par::Rayon(_)) if self.threads.is_none() => self.threads = Some(seconds),
            _ => {}
        }
    }

    /// Whether the threads were faster than one thread, once both were measured (a tie goes to
    /// one thread).
    pub(super) fn threads_won(&self) -> Option<bool> {
        Some(self.threads? < self.one?)
    }
}
