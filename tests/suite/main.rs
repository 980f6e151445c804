//! The integration tests, as one binary: its tests share the machine's cores as one queue
//! (a binary per file would run one after another, each idle while its slowest test ends),
//! and the library links once.

mod analysis_plan;
mod anisotropy;
mod architecture;
mod atlas;
mod bad_input;
mod cli;
mod common;
mod coverage;
mod digital_shift;
mod docs;
mod dual_lattice;
mod examples;
mod gaussian_jitter;
mod golden;
mod grid_exr;
mod halton;
mod integrand;
mod integrand_conformance;
mod io;
mod jitter_tent;
mod low_band;
mod measured_tail;
mod metrics;
mod montecarlo;
mod nufft;
mod output;
mod owen_gains;
mod padded;
mod pcf_route;
mod pilot;
mod pixels;
mod plan;
mod predict;
mod randomization;
mod rate;
mod rectangle;
mod render;
mod round_trip;
mod route;
mod sampler;
mod sampler_facts;
mod shifted_cells;
mod spectrum;
mod unshifted;
