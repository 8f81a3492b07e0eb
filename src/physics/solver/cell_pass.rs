//! Pass 1 of the assembly: the mixture properties of every cell at the
//! current iterate (density, ρ/μ, viscosity and their derivatives in p),
//! from the mixture EOS (`crate::physics::eos`, docs/model.md §2).

use super::work::{CellColumns, Work};
use super::Disc;
use crate::physics::eos::{exp_fast, CellConstants, MixtureEos};

/// Pass 1: mixture properties of every cell, bit-identical to
/// [`crate::physics::eos::MixtureEos::cell`], in blocks of [`CHUNK`]
/// cells. A block whose cells are all pure liquid (β(p − p0) beyond
/// saturation; about 40 % of the cells of a loaded contact) takes the
/// liquid's constants; any other block, and the cells past the last whole
/// one, take [`mixture_block`].
#[inline(always)]
pub(super) fn cell_pass(d: &Disc, p: &[f64], w: &mut Work) {
    let n = p.len();
    let k = d.eos.constants();
    let liquid = k.liquid();
    let c = &mut w.cells;
    let whole = n / CHUNK * CHUNK;
    for c0 in (0..whole).step_by(CHUNK) {
        let r = c0..c0 + CHUNK;
        if p[r.clone()]
            .iter()
            .fold(true, |all, &x| all & k.is_liquid(x))
        {
            c.rho[r.clone()].fill(liquid.rho);
            c.drho[r.clone()].fill(liquid.drho);
            c.gr[r.clone()].fill(liquid.gr);
            c.dgr[r.clone()].fill(liquid.dgr);
            c.mu[r.clone()].fill(liquid.mu);
            c.dmu[r].fill(liquid.dmu);
        } else {
            mixture_block(&d.eos, &k, &p[r], c, c0);
        }
    }
    mixture_block(&d.eos, &k, &p[whole..n], c, whole);
}

/// The cells of `p` (at most [`CHUNK`], the first being cell `i0`), in two
/// branch-free loops that vectorise: the exponentials [`exp_fast`] of every
/// cell, then the states (the saturated ones selected).
#[inline(always)]
fn mixture_block(eos: &MixtureEos, k: &CellConstants, p: &[f64], c: &mut CellColumns, i0: usize) {
    let m = p.len();
    let mut e = [0.0f64; CHUNK];
    let e = &mut e[..m];
    for (ej, &pj) in e.iter_mut().zip(p) {
        *ej = exp_fast(2.0 * eos.beta * (pj - eos.p0));
    }
    let r = i0..i0 + m;
    let (rho, drho, gr) = (
        &mut c.rho[r.clone()],
        &mut c.drho[r.clone()],
        &mut c.gr[r.clone()],
    );
    let (dgr, mu, dmu) = (&mut c.dgr[r.clone()], &mut c.mu[r.clone()], &mut c.dmu[r]);
    for j in 0..m {
        let s = k.state(p[j], e[j]);
        rho[j] = s.rho;
        drho[j] = s.drho;
        gr[j] = s.gr;
        dgr[j] = s.dgr;
        mu[j] = s.mu;
        dmu[j] = s.dmu;
    }
}

/// Cells per block of the cell pass. Eight AVX-512 vectors: a loop this
/// long vectorises whole, with no scalar remainder; measured at N = 256
/// against 8, 16, 32 and 128, 64 was fastest in both the liquid-rich and the
/// cavitating states of the cycle.
const CHUNK: usize = 64;

#[cfg(test)]
mod cell_pass_tests {
    //! The chunked cell pass equals the EOS evaluated cell by cell.
    use super::super::Solver;
    use super::*;
    use crate::physics::{ModelParams, SolverSettings};
    use proptest::prelude::*;

    fn bits(x: f64) -> u64 {
        x.to_bits()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Runs of liquid, mixture and vapour cells (and NaN), blocks all
        /// liquid and partly liquid, a partial block at the end: every
        /// column is `MixtureEos::cell` bit for bit.
        #[test]
        fn the_chunked_cell_pass_equals_the_eos_cell_by_cell(
            runs in prop::collection::vec(
                (
                    prop_oneof![
                        // Pure liquid, mixture near p0, vapour, NaN.
                        4 => 1e6..4e6f64,
                        2 => 0.0..2e5f64,
                        1 => -1e3..0.0f64,
                        1 => Just(f64::NAN),
                    ],
                    1..150usize,
                ),
                1..6,
            ),
        ) {
            let mut p: Vec<f64> = runs.iter().flat_map(|&(x, len)| vec![x; len]).collect();
            p.resize(p.len().max(8), 2e6);
            let st = SolverSettings { cells: p.len(), ..Default::default() };
            let mut s = Solver::new(&ModelParams::default(), &st).unwrap();
            cell_pass(&s.d, &p, &mut s.w);
            let c = &s.w.cells;
            for (i, &pi) in p.iter().enumerate() {
                let e = s.d.eos.cell(pi);
                let got = [c.rho[i], c.drho[i], c.gr[i], c.dgr[i], c.mu[i], c.dmu[i]];
                let want = [e.rho, e.drho, e.gr, e.dgr, e.mu, e.dmu];
                for (g, w) in got.iter().zip(&want) {
                    prop_assert_eq!(bits(*g), bits(*w), "cell {} at p = {}", i, pi);
                }
            }
        }
    }
}
