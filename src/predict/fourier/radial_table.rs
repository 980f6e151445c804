//! A closed form's radial mean, tabulated once for the polar form.
//!
//! The polar integral reads `P̆_S(ν)` tens of thousands of times, and a closed form's radial
//! mean is itself an angular quadrature (jitter's `1 − Π sinc²` averaged over the sphere: some
//! 800 products at `ν = 32` in 2D, 46 000 at `ν = 8` in 3D). `P̆_S` is smooth (analytic for
//! jitter), so it is interpolated instead: Chebyshev polynomials of degree 15 on panels a quarter
//! wide in `ν`, of `P̆_S(ν)/ν²` (smooth for a spectrum that rises like `ν²`, as jitter's does), so
//! that the table keeps its relative accuracy near DC, where at large N all of the integrand's
//! power lies. The interpolation's error is measured, not assumed: on every panel the closed
//! form is evaluated again between consecutive nodes and compared with the table, and the
//! largest relative gap, doubled for a gap between the check points, is the table's relative
//! error. Since the table is then within that fraction of `P̆_S` everywhere, the polar integral
//! `∫ W P̆_S` (W ≥ 0) is within that fraction of its value.

use crate::spectrum::ClosedForm;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::{Arc, Mutex};

/// Chebyshev nodes per panel.
const NODES: usize = 16;
/// Panel width in `ν`: a quarter of jitter's ripple period (its sinc² zeros are 1 apart).
const WIDTH: f64 = 0.25;

/// One panel `[i w, (i + 1) w]` of a table: its Chebyshev coefficients and the largest relative
/// gap measured between its nodes.
#[derive(Debug, Clone)]
struct Panel {
    coefficients: [f64; NODES],
    gap: f64,
}

/// The panels tabulated so far in this process, per form and dimension, the longest asked for.
/// A panel depends on its index alone, so a table read from a longer one's first panels is the
/// table built afresh, bit for bit, its error included; a rate study or a test that predicts
/// jitter at many counts tabulates each panel once.
static TABULATED: Mutex<Vec<(TableKey, Arc<Vec<Panel>>)>> = Mutex::new(Vec::new());

/// A table's form and dimension.
type TableKey = (ClosedForm, usize);

/// `P̆_S(ν)` on `[0, ν_end]` by piecewise Chebyshev interpolation.
#[derive(Debug, Clone)]
pub(crate) struct RadialTable {
    /// The panels, of which the table reads the first `count`.
    panels: Arc<Vec<Panel>>,
    count: usize,
    /// A bound on `|table − P̆_S| / P̆_S` on `(0, end]`, measured (see the module notes).
    error: f64,
}

impl RadialTable {
    /// Tabulates `closed`'s radial mean in dimension `d` on `[0, end]`, the panels in parallel
    /// (those this process has not tabulated yet). `None` for a form without a radial mean.
    pub(crate) fn new(closed: ClosedForm, d: usize, end: f64) -> Option<Self> {
        closed.radial(d, 1.0)?;
        let count = (end / WIDTH).ceil().max(1.0) as usize;
        let key = (closed, d);
        let known = {
            let tabulated = TABULATED.lock().unwrap_or_else(|e| e.into_inner());
            tabulated
                .iter()
                .find(|(k, _)| *k == key)
                .map(|(_, panels)| Arc::clone(panels))
        };
        let panels = match known {
            Some(panels) if panels.len() >= count => panels,
            known => {
                // Built without the lock held: a panel's work runs on the pool, where a thread
                // waiting for it may pick up another table's request.
                let mut panels: Vec<Panel> = known.map_or_else(Vec::new, |p| p.to_vec());
                let exact = |nu: f64| closed.radial(d, nu).unwrap_or(1.0);
                panels.par_extend(
                    (panels.len()..count)
                        .into_par_iter()
                        .map(|i| panel(&exact, i)),
                );
                let panels = Arc::new(panels);
                let mut tabulated = TABULATED.lock().unwrap_or_else(|e| e.into_inner());
                match tabulated.iter_mut().find(|(k, _)| *k == key) {
                    Some((_, longest)) if longest.len() < panels.len() => {
                        *longest = Arc::clone(&panels)
                    }
                    Some(_) => {}
                    None => tabulated.push((key, Arc::clone(&panels))),
                }
                panels
            }
        };
        let error = 2.0 * panels[..count].iter().map(|p| p.gap).fold(0.0, f64::max);
        Some(Self {
            panels,
            count,
            error,
        })
    }

    /// The end of the table.
    fn end(&self) -> f64 {
        self.count as f64 * WIDTH
    }

    /// `P̆_S(ν)`, or `None` outside the table.
    pub(crate) fn at(&self, nu: f64) -> Option<f64> {
        if !(0.0..=self.end()).contains(&nu) {
            return None;
        }
        let i = ((nu / WIDTH) as usize).min(self.count - 1);
        let a = i as f64 * WIDTH;
        let t = 2.0 * (nu - a) / WIDTH - 1.0;
        Some(nu * nu * clenshaw(&self.panels[i].coefficients, t))
    }

    /// The measured bound on the interpolation's relative error.
    pub(crate) fn error(&self) -> f64 {
        self.error
    }
}

/// Panel `i` of the table of `exact`: the interpolant of `exact(ν)/ν²` on `[i w, (i + 1) w]`,
/// checked between its nodes.
fn panel(exact: &impl Fn(f64) -> f64, i: usize) -> Panel {
    let (a, b) = (i as f64 * WIDTH, (i + 1) as f64 * WIDTH);
    let nu = |t: f64| a + (b - a) * (t + 1.0) / 2.0;
    // The nodes are inside the panel, so ν > 0 at every one.
    let coefficients = chebyshev_coefficients(|t| exact(nu(t)) / nu(t).powi(2));
    // Between consecutive nodes t_j = cos(π(j + 1/2)/K): at cos(π(j + 1)/K).
    let gap = (0..NODES - 1)
        .map(|j| {
            let t = (PI * (j + 1) as f64 / NODES as f64).cos();
            let truth = exact(nu(t));
            (nu(t).powi(2) * clenshaw(&coefficients, t) - truth).abs() / truth.abs()
        })
        .fold(0.0, f64::max);
    Panel { coefficients, gap }
}

/// The coefficients `c_k` of `Σ c_k T_k(t)` interpolating `f` at the Chebyshev nodes on
/// `[-1, 1]` (the first halved, so that the sum is evaluated as written).
fn chebyshev_coefficients(f: impl Fn(f64) -> f64) -> [f64; NODES] {
    let values: Vec<f64> = (0..NODES)
        .map(|j| f((PI * (j as f64 + 0.5) / NODES as f64).cos()))
        .collect();
    let mut c = [0.0; NODES];
    for (k, ck) in c.iter_mut().enumerate() {
        let sum: f64 = values
            .iter()
            .enumerate()
            .map(|(j, v)| v * (PI * k as f64 * (j as f64 + 0.5) / NODES as f64).cos())
            .sum();
        *ck = 2.0 * sum / NODES as f64;
    }
    c[0] /= 2.0;
    c
}

/// `Σ c_k T_k(t)` by Clenshaw's recurrence.
fn clenshaw(c: &[f64; NODES], t: f64) -> f64 {
    let (mut b1, mut b2) = (0.0, 0.0);
    for &ck in c.iter().skip(1).rev() {
        let b0 = 2.0 * t * b1 - b2 + ck;
        b2 = b1;
        b1 = b0;
    }
    t * b1 - b2 + c[0]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table reproduces the closed form at points it was not built on, within its
    /// measured error, in 1D to 3D.
    #[test]
    fn the_table_agrees_with_the_closed_form_within_its_error() {
        for (d, end) in [(1, 32.0), (2, 32.0), (3, 8.0)] {
            let table = RadialTable::new(ClosedForm::Jitter, d, end).expect("jitter is radial");
            assert!(table.error() < 1e-10, "d = {d}: {}", table.error());
            for i in 0..200 {
                let nu = end * (i as f64 + 0.37) / 200.0;
                let exact = ClosedForm::Jitter.radial(d, nu).unwrap();
                let got = table.at(nu).unwrap();
                assert!(
                    (got - exact).abs() <= table.error().max(1e-15) * exact,
                    "d = {d}, ν = {nu}"
                );
            }
            // Near DC it keeps its relative accuracy: jitter rises like π²ν²/3 there.
            for tiny in [1e-7, 1e-12] {
                let rise = PI * PI * tiny * tiny / 3.0;
                assert!(
                    (table.at(tiny).unwrap() / rise - 1.0).abs() < 1e-6,
                    "d = {d}"
                );
            }
            assert!(table.at(end + 1.0).is_none());
        }
        assert!(RadialTable::new(ClosedForm::LatinHypercube, 2, 4.0).is_none());
    }

    /// A table read from the first panels of a longer one is the table built afresh: the same
    /// coefficients, gaps, error and values, whatever was tabulated before.
    #[test]
    fn a_table_read_from_a_longer_one_is_built_afresh() {
        let long = RadialTable::new(ClosedForm::Jitter, 2, 6.0).unwrap();
        let short = RadialTable::new(ClosedForm::Jitter, 2, 2.0).unwrap();
        let exact = |nu: f64| ClosedForm::Jitter.radial(2, nu).unwrap();
        let fresh: Vec<Panel> = (0..8).map(|i| panel(&exact, i)).collect();
        assert_eq!(short.count, fresh.len());
        for (read, built) in short.panels.iter().zip(&fresh) {
            assert_eq!(read.coefficients, built.coefficients);
            assert_eq!(read.gap.to_bits(), built.gap.to_bits());
        }
        let error = 2.0 * fresh.iter().map(|p| p.gap).fold(0.0, f64::max);
        assert_eq!(short.error().to_bits(), error.to_bits());
        assert!(long.error() >= short.error());
        for i in 0..100 {
            let nu = 2.0 * (i as f64 + 0.5) / 100.0;
            assert_eq!(short.at(nu), long.at(nu), "ν = {nu}");
        }
        assert!(short.at(2.5).is_none());
    }
}
