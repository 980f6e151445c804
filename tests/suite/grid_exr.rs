//! OpenEXR grids: values as written (linear, unbounded), rows as for PNG (the top row at the
//! top of the square), luminance from R, G, B, or the Y channel.

use exr::prelude::*;
use specvar::integrand::{read_grid_file, Integrand};

fn scratch(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("specvar-exr-{}-{name}", std::process::id()))
}

#[test]
fn an_rgb_exr_is_read_as_its_luminance_with_the_top_row_at_the_top() {
    let (w, h) = (4, 3);
    // Red ramps along x, blue marks the top row; values beyond 1 stay as they are.
    let image = Image::from_channels(
        (w, h),
        SpecificChannels::rgb(|Vec2(x, y)| {
            (x as f32 * 2.0, 0.5f32, if y == 0 { 1.0f32 } else { 0.0 })
        }),
    );
    let path = scratch("rgb.exr");
    image.write().to_file(&path).unwrap();
    let grid = read_grid_file(&path).unwrap();
    let luma = |x: usize, top: bool| {
        0.2126 * x as f64 * 2.0 + 0.7152 * 0.5 + if top { 0.0722 } else { 0.0 }
    };
    // Cell centres: the file's row 0 is the square's top row (y near 1).
    let at = |x: usize, row: usize| {
        grid.eval(&[
            (x as f64 + 0.5) / w as f64,
            1.0 - (row as f64 + 0.5) / h as f64,
        ])
    };
    for x in 0..w {
        assert!((at(x, 0) - luma(x, true)).abs() < 1e-6, "top row, x = {x}");
        assert!(
            (at(x, 2) - luma(x, false)).abs() < 1e-6,
            "bottom row, x = {x}"
        );
    }
    assert!(
        grid.eval(&[0.9, 0.5]) > 1.0,
        "values are not scaled to [0, 1]"
    );
    std::fs::remove_file(path).ok();
}

#[test]
fn a_luminance_exr_is_read_from_its_y_channel() {
    let values: Vec<f32> = (0..6).map(|i| i as f32 * 0.25).collect();
    let channels = AnyChannels::sort(SmallVec::from_vec(vec![AnyChannel::new(
        "Y",
        FlatSamples::F32(values.clone()),
    )]));
    let layer = Layer::new(
        (3, 2),
        LayerAttributes::named("pixel"),
        Encoding::FAST_LOSSLESS,
        channels,
    );
    let path = scratch("y.exr");
    Image::from_layer(layer).write().to_file(&path).unwrap();
    let grid = read_grid_file(&path).unwrap();
    let mean = values.iter().map(|&v| v as f64).sum::<f64>() / 6.0;
    assert!((grid.integral() - mean).abs() < 1e-12);
    assert!(
        (grid.eval(&[0.1, 0.9]) - 0.0).abs() < 1e-12,
        "the file's first value, top left"
    );
    std::fs::remove_file(path).ok();
}

#[test]
fn a_truncated_exr_is_a_format_error() {
    let image = Image::from_channels((8, 8), SpecificChannels::rgb(|_| (1.0f32, 1.0f32, 1.0f32)));
    let path = scratch("cut.exr");
    image.write().to_file(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    let e = read_grid_file(&path).unwrap_err();
    assert!(e.to_string().contains("OpenEXR"), "{e}");
    std::fs::remove_file(path).ok();
}
