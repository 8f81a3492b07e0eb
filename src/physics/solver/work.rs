//! The solver's scratch memory, allocated once in [`super::Solver::new`]
//! and reused by every iteration: the per-cell mixture properties, the
//! face fluxes, the rows of the bordered system, its factors and the
//! buffers of Newton, post-processing and the reference solver. Laid out in
//! columns (one array per quantity) so that the passes over it vectorise.
//! Nothing here computes; the passes that fill it are `cell_pass.rs`,
//! `assembly.rs` and `bordered.rs`.

/// Mixture properties of one cell at the current iterate.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct CellProps {
    pub rho: f64,
    pub drho: f64,
    /// ρ/μ and its pressure derivative.
    pub gr: f64,
    pub dgr: f64,
}

/// Mixture properties of every cell (one column per property, so the
/// loops over cells vectorise).
#[derive(Debug, Clone)]
pub(crate) struct CellColumns {
    pub rho: Vec<f64>,
    pub drho: Vec<f64>,
    /// ρ/μ and its pressure derivative.
    pub gr: Vec<f64>,
    pub dgr: Vec<f64>,
    pub mu: Vec<f64>,
    pub dmu: Vec<f64>,
}

impl CellColumns {
    pub(super) fn new(n: usize) -> Self {
        Self {
            rho: vec![0.0; n],
            drho: vec![0.0; n],
            gr: vec![0.0; n],
            dgr: vec![0.0; n],
            mu: vec![0.0; n],
            dmu: vec![0.0; n],
        }
    }

    #[inline(always)]
    pub(super) fn props(&self, i: usize) -> CellProps {
        CellProps {
            rho: self.rho[i],
            drho: self.drho[i],
            gr: self.gr[i],
            dgr: self.dgr[i],
        }
    }
}

/// Mass flux through one face and its derivatives.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct FaceFlux {
    pub q: f64,
    pub dql: f64,
    pub dqr: f64,
    pub dqh: f64,
}

/// Mass flux through every face (N + 1) and its derivatives in the left and
/// right pressure and in h0; with a MUSCL flux also in the pressure of the
/// far upwind cell (`dqx`: the cell left of the left one when v ≥ 0, right
/// of the right one when v < 0).
#[derive(Debug, Clone)]
pub(crate) struct FaceColumns {
    pub q: Vec<f64>,
    pub dql: Vec<f64>,
    pub dqr: Vec<f64>,
    pub dqh: Vec<f64>,
    pub dqx: Vec<f64>,
}

impl FaceColumns {
    pub(super) fn new(faces: usize) -> Self {
        Self {
            q: vec![0.0; faces],
            dql: vec![0.0; faces],
            dqr: vec![0.0; faces],
            dqh: vec![0.0; faces],
            dqx: vec![0.0; faces],
        }
    }

    #[inline(always)]
    pub(super) fn set(&mut self, i: usize, f: FaceFlux) {
        self.q[i] = f.q;
        self.dql[i] = f.dql;
        self.dqr[i] = f.dqr;
        self.dqh[i] = f.dqh;
    }
}

/// The bordered system, one column per coefficient: tridiagonal (a, b, c),
/// border column ∂R/∂h0 (`col`), residual (`r`); with a MUSCL flux the
/// second sub- and super-diagonals (`a2`: ∂R_i/∂p_(i−2), `c2`:
/// ∂R_i/∂p_(i+2); one of them is zero, by the sign of v).
#[derive(Debug, Clone)]
pub(crate) struct RowColumns {
    pub a: Vec<f64>,
    pub b: Vec<f64>,
    pub c: Vec<f64>,
    pub col: Vec<f64>,
    pub r: Vec<f64>,
    pub a2: Vec<f64>,
    pub c2: Vec<f64>,
    /// The outer diagonal is `c2` (rows built for v < 0): the banded solve
    /// runs from the last row to the first.
    pub reversed: bool,
}

impl RowColumns {
    pub(super) fn new(n: usize) -> Self {
        Self {
            a: vec![0.0; n],
            b: vec![0.0; n],
            c: vec![0.0; n],
            col: vec![0.0; n],
            r: vec![0.0; n],
            a2: vec![0.0; n],
            c2: vec![0.0; n],
            reversed: false,
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.b.len()
    }
}

/// Work arrays (allocated once).
#[derive(Debug, Clone)]
pub(crate) struct Work {
    pub cells: CellColumns,
    pub faces: FaceColumns,
    pub rows: RowColumns,
    pub g: f64,
    pub dgdh: f64,
    pub f_net: f64,
    pub factors: Vec<Factor>,
    /// Factors of the banded (MUSCL) system, used when `banded`.
    pub band: Vec<BandFactor>,
    /// z = A⁻¹ ∂R/∂h0 of the banded system (storage order).
    pub band_z: Vec<f64>,
    /// The banded factors are in reversed order (rows built for v < 0).
    pub band_reversed: bool,
    /// The rows are pentadiagonal (a MUSCL flux): `bordered.rs` hands the
    /// solve to `banded.rs`.
    pub banded: bool,
    pub schur: f64,
    pub c_row: f64,
    pub balance: bool,
    /// Scratch of length N (post-processing, Picard).
    pub tmp: Vec<f64>,
    /// Scratch of length N (post-processing: μ, then the shear per cell).
    pub shear: Vec<f64>,
    pub dp: Vec<f64>,
    pub dbar: Vec<f64>,
    pub p_trial: Vec<f64>,
    /// The vapour-fraction map of a large Newton update (newton.rs): U(p)
    /// and U'(p)Δp per cell.
    pub map_u: Vec<f64>,
    pub map_du: Vec<f64>,
    pub p_backup: Vec<f64>,
    pub p_anchor: Vec<f64>,
    pub source: Vec<f64>,
    pub has_source: bool,
    /// Σ_k≥1 (history storage and flux terms) per cell, valid for the
    /// coefficients it was computed with (reset when the history changes).
    pub hist_term: Vec<f64>,
    #[allow(clippy::type_complexity)]
    pub hist_term_valid: Option<Option<([f64; 3], [f64; 3], f64)>>,
    /// Set when the state is the last assembly point plus the update
    /// (`dp`, Δh0): post-processing then linearises instead of re-evaluating.
    pub linearised: Option<f64>,
}

impl Work {
    pub(super) fn new(n: usize) -> Self {
        Self {
            cells: CellColumns::new(n),
            faces: FaceColumns::new(n + 1),
            rows: RowColumns::new(n),
            g: 0.0,
            dgdh: 0.0,
            f_net: 0.0,
            factors: vec![Factor::default(); n],
            band: vec![BandFactor::default(); n],
            band_z: vec![0.0; n],
            band_reversed: false,
            banded: false,
            schur: 0.0,
            c_row: 0.0,
            balance: true,
            tmp: vec![0.0; n],
            shear: vec![0.0; n],
            dp: vec![0.0; n],
            dbar: vec![0.0; n],
            p_trial: vec![0.0; n],
            map_u: vec![0.0; n],
            map_du: vec![0.0; n],
            p_backup: vec![0.0; n],
            p_anchor: vec![0.0; n],
            source: vec![0.0; n],
            has_source: false,
            hist_term: vec![0.0; n],
            hist_term_valid: None,
            linearised: None,
        }
    }
}

/// Factors of one row, the block's spike and z = A⁻¹ col. `fa` is the
/// coupling to the already-eliminated neighbour (a above the block's meeting
/// row, c below it) and `cp` the multiplier of the other neighbour.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Factor {
    pub fa: f64,
    pub cp: f64,
    pub inv_m: f64,
    pub z: f64,
    /// The block's spike (v in the first block, u in the second).
    pub s: f64,
}

/// One row of the twisted banded factors (no pivoting) of the
/// pentadiagonal system, in solve order (`banded.rs`). Above the meeting
/// row: the multipliers of the two rows above (`l2`, `l1`), the inverse
/// pivot and the entry right of it (`u1`). Below it: the multiplier of the
/// row below (`l1`), the inverse pivot and the two entries left of it
/// (`u1`, `u2`). The meeting row: `l2`, `l1`, its inverse pivot and the
/// multiplier of the row below (`u2`).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct BandFactor {
    pub l2: f64,
    pub l1: f64,
    pub inv_d: f64,
    pub u1: f64,
    pub u2: f64,
}
