//! Image-level predictions over a stack of per-pixel grids, `.npy` grids and grid scales.

use crate::common;

use specvar::integrand::{
    read_grid_file, read_grid_text, GridIntegrand, GridMeaning, Integrand, IntegrandSpec,
};
use specvar::montecarlo::{empirical_variance, McParams};
use specvar::npy::read_npy;
use specvar::pixels::{pixel_params, predict_pixels, PixelStack};
use specvar::predict::{predict, PredictParams, Problem};
use specvar::progress::Silent;
use specvar::randomization::{Randomization, RandomizationChoice};
use specvar::sampler::{Jitter, SamplerKind};

/// A fresh scratch directory for this test.
fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("specvar-pixels-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A `.npy` file of `f8` values with this shape, as `numpy.save` writes it.
fn npy(shape: &[usize], values: &[f64]) -> Vec<u8> {
    let dims: Vec<String> = shape.iter().map(|s| s.to_string()).collect();
    let tuple = if dims.len() == 1 {
        format!("({},)", dims[0])
    } else {
        format!("({})", dims.join(", "))
    };
    let header = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': {tuple}, }}");
    let mut padded = header;
    while !(10 + padded.len() + 1).is_multiple_of(64) {
        padded.push(' ');
    }
    padded.push('\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend_from_slice(&(padded.len() as u16).to_le_bytes());
    bytes.extend_from_slice(padded.as_bytes());
    for v in values {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    bytes
}

/// A soft edge at `angle` degrees through `offset`, over a gradient (a seam at the faces), on
/// `m × m` cells `values[y][x]`.
fn soft_edge(m: usize, angle: f64, offset: f64) -> Vec<f64> {
    let (c, s) = (angle.to_radians().cos(), angle.to_radians().sin());
    (0..m * m)
        .map(|i| {
            let (x, y) = (
                ((i % m) as f64 + 0.5) / m as f64,
                ((i / m) as f64 + 0.5) / m as f64,
            );
            let t = ((x * c + y * s - offset) / 0.1 + 0.5).clamp(0.0, 1.0);
            0.2 + 0.6 * t * t * (3.0 - 2.0 * t) + 0.2 * x
        })
        .collect()
}

fn stack_values(rows: usize, columns: usize, m: usize) -> Vec<f64> {
    (0..rows * columns)
        .flat_map(|p| {
            soft_edge(
                m,
                10.0 + 15.0 * (p % columns) as f64,
                0.3 + 0.1 * (p / columns) as f64,
            )
        })
        .collect()
}

#[test]
fn stacks_read_from_arrays_of_rank_three_and_four() {
    let values = stack_values(2, 3, 8);
    let four = PixelStack::from_array(read_npy(&npy(&[2, 3, 8, 8], &values)).unwrap()).unwrap();
    assert_eq!((four.columns(), four.rows()), (3, 2));
    let three = PixelStack::from_array(read_npy(&npy(&[6, 8, 8], &values)).unwrap()).unwrap();
    assert_eq!((three.columns(), three.rows()), (6, 1));
    assert_eq!(four.pixels()[4].values(), three.pixels()[4].values());
    assert!(PixelStack::from_array(read_npy(&npy(&[6, 64], &values)).unwrap()).is_err());
}

#[test]
fn each_pixel_is_its_own_prediction_and_the_image_is_their_mean() {
    let (rows, columns, m) = (2, 3, 16);
    let values = stack_values(rows, columns, m);
    let stack = PixelStack::from_array(read_npy(&npy(&[rows, columns, m, m], &values)).unwrap())
        .unwrap()
        .with_meaning(GridMeaning::Exact);
    let jitter = Jitter::new(2).unwrap();
    let params = pixel_params(&PredictParams::default());
    let image = predict_pixels(
        &stack,
        &jitter,
        64,
        RandomizationChoice::Native,
        &params,
        &Silent,
    )
    .unwrap();
    assert_eq!(image.randomization, Randomization::None);
    let mut sum = 0.0;
    for (pixel, f) in image.pixels.iter().zip(stack.pixels()) {
        // Jitter as drawn is exact (the per-stratum form): the same value alone.
        let alone = predict(&Problem::new(&jitter, f, 64).unwrap(), &params).unwrap();
        assert_eq!(pixel.variance, alone.variance);
        sum += alone.variance;
    }
    assert!(common::close(image.mse, sum / 6.0, 1e-14));
    let png = image.variance_png().unwrap();
    assert!(png.starts_with(b"\x89PNG"));
}

#[test]
fn the_image_mse_agrees_with_monte_carlo_of_every_pixel() {
    let (rows, columns, m) = (1, 4, 32);
    let values = stack_values(rows, columns, m);
    let stack = PixelStack::from_array(read_npy(&npy(&[rows, columns, m, m], &values)).unwrap())
        .unwrap()
        .with_meaning(GridMeaning::Exact);
    let kind = SamplerKind::Cmj;
    let cmj = kind.build(2).unwrap();
    let params = pixel_params(&PredictParams::default());
    let image = predict_pixels(
        &stack,
        cmj.as_ref(),
        64,
        RandomizationChoice::Native,
        &params,
        &Silent,
    )
    .unwrap();
    // The pixels' Monte Carlo runs are independent: their mean's interval from theirs.
    let mc: Vec<_> = stack
        .pixels()
        .iter()
        .map(|f| {
            let p = McParams::pooled(kind, 20_000, 3, Randomization::None);
            empirical_variance(cmj.as_ref(), f, 64, &p).unwrap()
        })
        .collect();
    let measured = mc.iter().map(|r| r.variance).sum::<f64>() / 4.0;
    let half = mc
        .iter()
        .map(|r| ((r.ci_high - r.ci_low) / 2.0).powi(2))
        .sum::<f64>()
        .sqrt()
        / 4.0;
    let predicted_half = image.budget.half_width(specvar::montecarlo::Z_99);
    assert!(
        (image.mse - measured).abs() <= half + predicted_half,
        "predicted {:.4e} ± {predicted_half:.1e}, measured {measured:.4e} ± {half:.1e}",
        image.mse
    );
}

#[test]
fn npy_grids_keep_row_zero_at_the_bottom_and_scales_multiply() {
    let dir = scratch("npy");
    // values[y][x]: row 0 (y near 0) is [1, 0].
    let path = dir.join("g.npy");
    std::fs::write(&path, npy(&[2, 2], &[1.0, 0.0, 0.0, 0.0])).unwrap();
    let from_npy = read_grid_file(&path)
        .unwrap()
        .with_meaning(GridMeaning::Exact);
    // A text grid's first line is the top row.
    let from_text = read_grid_text("0 0\n1 0\n").unwrap();
    assert_eq!(from_npy.values(), from_text.values());
    assert_eq!(from_npy.eval(&[0.1, 0.1]), 1.0);
    let spec: IntegrandSpec = format!("grid:{},a=0.5,exact", path.display())
        .parse()
        .unwrap();
    let half = spec.build(2).unwrap();
    assert_eq!(half.integral(), 0.5 * from_npy.integral());
    let jitter = Jitter::new(2).unwrap();
    let params = PredictParams::default();
    let v = |f: &dyn Integrand| {
        predict(&Problem::new(&jitter, f, 1).unwrap(), &params)
            .unwrap()
            .variance
    };
    assert!(common::close(v(half.as_ref()), 0.25 * v(&from_npy), 1e-12));
    assert!("grid:x.png,a=0".parse::<IntegrandSpec>().is_err());
    assert!("grid:x.png,a=nan".parse::<IntegrandSpec>().is_err());
}

#[test]
fn a_directory_of_grids_is_a_row_of_pixels() {
    let dir = scratch("directory");
    for (i, offset) in [0.3, 0.5, 0.7].iter().enumerate() {
        let values = soft_edge(8, 20.0, *offset);
        let grid = GridIntegrand::new(8, 8, values.clone())
            .unwrap()
            .with_meaning(specvar::integrand::GridMeaning::Exact);
        assert_eq!(grid.values().len(), 64);
        std::fs::write(dir.join(format!("p{i}.npy")), npy(&[8, 8], &values)).unwrap();
    }
    let stack = PixelStack::read(&dir).unwrap();
    assert_eq!((stack.columns(), stack.rows()), (3, 1));
}
