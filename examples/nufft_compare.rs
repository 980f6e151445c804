//! The specvar side of the FINUFFT comparison (`benches/compare/vs_finufft.py`): reads the point
//! sets the script wrote, transforms them with one plan per run and one scratch per thread, and
//! prints one JSON line of timings. Not meant to be run by hand.
//!
//! `nufft_compare POINTS D N R K TOLERANCE THREADS SUMS_OUT`: `POINTS` holds `R` sets of `N`
//! points in `D` dimensions as little-endian `f64`; the sums of the first set are written to
//! `SUMS_OUT` (little-endian `f64` pairs, lattice order) for the script to check.

use num_complex::Complex64;
use rayon::prelude::*;
use specvar::spectrum::nufft::NufftPlan;
use specvar::PointSet;
use std::sync::Mutex;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [path, d, n, r, k, tolerance, threads, sums_out] = args.as_slice() else {
        return Err("usage: nufft_compare POINTS D N R K TOLERANCE THREADS SUMS_OUT".into());
    };
    let (d, n, r, k): (usize, usize, usize, usize) =
        (d.parse()?, n.parse()?, r.parse()?, k.parse()?);
    let (tolerance, threads): (f64, usize) = (tolerance.parse()?, threads.parse()?);
    let bytes = std::fs::read(path)?;
    let coords: Vec<f64> = bytes
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
        .collect();
    if coords.len() != r * n * d {
        return Err(format!("{} coordinates, expected {}", coords.len(), r * n * d).into());
    }
    let sets = coords
        .chunks_exact(n * d)
        .map(|c| PointSet::new(d, c.to_vec()))
        .collect::<specvar::Result<Vec<_>>>()?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let plan = NufftPlan::new(d, k, n, tolerance)?;
    let zero = Complex64::new(0.0, 0.0);
    // One scratch and output per thread, made once: as a spectrum estimate keeps them.
    let buffers: Vec<Mutex<_>> = (0..threads)
        .map(|_| Mutex::new((plan.make_scratch(), vec![zero; plan.output_len()])))
        .collect();
    let run = |sets: &[PointSet]| {
        pool.install(|| {
            let chunk = sets.len().div_ceil(threads);
            sets.par_chunks(chunk).enumerate().for_each(|(t, part)| {
                let mut guard = buffers[t].lock().expect("no panics while held");
                let (scratch, sums) = &mut *guard;
                for set in part {
                    plan.sums_with_scratch(set, scratch, sums)
                        .expect("a plan of this dimension");
                }
            })
        })
    };
    // Warm up: page in the scratch and the FFT twiddles.
    run(&sets[..threads.min(sets.len())]);
    let start = Instant::now();
    run(&sets);
    let per_set = start.elapsed().as_secs_f64() / r as f64;
    // The FFT stage alone: one point per set (spreading is then negligible).
    let single = PointSet::new(d, vec![0.5; d])?;
    let lone: Vec<PointSet> = (0..r).map(|_| single.clone()).collect();
    let start = Instant::now();
    run(&lone);
    let fft = start.elapsed().as_secs_f64() / r as f64;
    let sums = plan.sums(&sets[0])?;
    let out: Vec<u8> = sums
        .iter()
        .flat_map(|s| [s.re.to_le_bytes(), s.im.to_le_bytes()])
        .flatten()
        .collect();
    std::fs::write(sums_out, out)?;
    println!(
        "{{\"seconds_per_set\": {per_set:e}, \"fft_seconds_per_set\": {fft:e}, \"upsampling\": {}, \
         \"grid\": {}, \"width\": {}, \"error_bound\": {:e}}}",
        plan.upsampling(),
        plan.grid_size(),
        plan.width(),
        plan.error_bound()
    );
    Ok(())
}
