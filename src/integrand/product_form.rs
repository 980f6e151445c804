//! Integrands that are products of functions of one coordinate each, every factor analytic
//! between a few breakpoints ([`Integrand::product_form`](super::Integrand::product_form)).
//!
//! A product's Walsh coefficients are products of its factors' (`f̌(κ) = a Π_l ǧ_l(κ_l)`), so a
//! sum over Walsh frequencies factors into one table per axis: the exact form of a digitally
//! shifted net reads such tables (`docs/theory.md`, "Digital shifts of a linear net").

use super::gaussian::axis_mass;
use crate::vector_exp::exp_nonpositive;

/// One axis's factor of a product integrand on `[0, 1)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AxisFactor {
    /// `exp(−(x − centre)² / (2 σ²))`, analytic on the whole axis.
    Gaussian {
        /// The centre.
        centre: f64,
        /// The width σ.
        sigma: f64,
    },
    /// 1 on `[lo, hi)`, 0 elsewhere: constant between its two breakpoints.
    Interval {
        /// The lower end.
        lo: f64,
        /// The upper end.
        hi: f64,
    },
}

impl AxisFactor {
    /// The factor at `x`.
    pub fn eval(&self, x: f64) -> f64 {
        match *self {
            AxisFactor::Gaussian { centre, sigma } => {
                let t = x - centre;
                exp_nonpositive(-t * t / (2.0 * sigma * sigma))
            }
            AxisFactor::Interval { lo, hi } => f64::from(u8::from((lo..hi).contains(&x))),
        }
    }
    /// `∫_0^1` of the factor, exactly.
    pub fn integral(&self) -> f64 {
        match *self {
            AxisFactor::Gaussian { centre, sigma } => axis_mass(0.0, 1.0, centre, sigma),
            AxisFactor::Interval { lo, hi } => hi.min(1.0) - lo.max(0.0),
        }
    }
    /// The points of `(0, 1)` where the factor is not analytic (its jumps): between them a
    /// Gauss–Legendre rule converges geometrically.
    pub fn breakpoints(&self) -> Vec<f64> {
        match *self {
            AxisFactor::Gaussian { .. } => Vec::new(),
            AxisFactor::Interval { lo, hi } => [lo, hi]
                .into_iter()
                .filter(|&b| 0.0 < b && b < 1.0)
                .collect(),
        }
    }
}

/// An integrand written as `height · Π_l axes[l](x_l)`.
///
/// # Examples
/// ```
/// use specvar::integrand::{AxisFactor, Gaussian, Integrand};
/// let f = Gaussian::new(0.2, vec![0.2, 0.7], 1.0)?;
/// let form = f.product_form().expect("a Gaussian is a product of one factor per axis");
/// assert_eq!(form.axes[1], AxisFactor::Gaussian { centre: 0.7, sigma: 0.2 });
/// let x = [0.3, 0.6];
/// assert!((form.eval(&x) - f.eval(&x)).abs() < 1e-15);
/// # Ok::<(), specvar::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct ProductForm {
    /// The factor common to every point.
    pub height: f64,
    /// One factor per axis.
    pub axes: Vec<AxisFactor>,
}

impl ProductForm {
    /// The integrand at `x`: the height times every axis's factor.
    pub fn eval(&self, x: &[f64]) -> f64 {
        self.axes
            .iter()
            .zip(x)
            .fold(self.height, |p, (g, &t)| p * g.eval(t))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrature::GaussLegendre;

    /// Each factor's integral against a quadrature between its breakpoints.
    #[test]
    fn the_integrals_are_those_of_the_factors() {
        let rule = GaussLegendre::new(40);
        for g in [
            AxisFactor::Gaussian {
                centre: 0.2,
                sigma: 0.15,
            },
            AxisFactor::Interval { lo: 0.3, hi: 0.65 },
            AxisFactor::Interval { lo: 0.0, hi: 0.5 },
        ] {
            let mut ends = vec![0.0];
            ends.extend(g.breakpoints());
            ends.push(1.0);
            let q: f64 = ends
                .windows(2)
                .map(|w| rule.integrate(w[0], w[1], |x| g.eval(x)))
                .sum();
            assert!((q - g.integral()).abs() < 1e-14, "{g:?}: {q}");
        }
    }

    /// Gaussians and axis-aligned rectangles have the form, and it is the integrand (off the
    /// rectangle's edges, where the two may take either side's value); a disk and a rotated
    /// square have none.
    #[test]
    fn the_form_is_the_integrand_where_there_is_one() {
        let build = |text: &str, d: usize| {
            crate::integrand::parse_integrand(text)
                .and_then(|s| s.build(d))
                .unwrap()
        };
        let rectangle = crate::integrand::Polygon::new(
            vec![[0.2, 0.3], [0.7, 0.3], [0.7, 0.8], [0.2, 0.8]],
            -2.0,
        )
        .unwrap();
        for (text, f) in [
            (
                "gaussian:sigma=0.2,c=0.2;0.7,a=3",
                build("gaussian:sigma=0.2,c=0.2;0.7,a=3", 2),
            ),
            (
                "gaussian:sigma=0.1,c=0.3",
                build("gaussian:sigma=0.1,c=0.3", 3),
            ),
            ("rectangle of height −2", Box::new(rectangle)),
            (
                "edge:theta=90,offset=0.37",
                build("edge:theta=90,offset=0.37", 2),
            ),
            (
                "edge:theta=-180,offset=0.6",
                build("edge:theta=-180,offset=0.6", 2),
            ),
        ] {
            let d = f.dimension();
            let form = f.product_form().unwrap_or_else(|| panic!("{text}"));
            for i in 0..200 {
                let x: Vec<f64> = (0..d)
                    .map(|l| ((i * (7 + 6 * l) + 3 * l) % 199) as f64 / 199.0 + 1e-3)
                    .collect();
                let (a, b) = (f.eval(&x), form.eval(&x));
                assert!((a - b).abs() <= 1e-15 * a.abs().max(1.0), "{text} {x:?}");
            }
        }
        for text in [
            "disk",
            "polygon:0.5,0.1;0.9,0.5;0.5,0.9;0.1,0.5",
            "edge:theta=30,offset=0.4",
        ] {
            assert!(build(text, 2).product_form().is_none(), "{text}");
        }
    }
}
