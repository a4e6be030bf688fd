//! Every integration test of fmu-harness in one test binary: one compile and one link of the
//! engine's rlib instead of one per file (issue 46 item 6: the Rust tests' compile was 2 of
//! `make test`'s minutes). Each file is a module of the name its binary had: nextest names a
//! test `integration <file>::<test>`, and `cargo test --test integration <file>::` runs one file.

mod common;

mod accuracy_study;
mod animate_format;
mod cosim_c_oscillator;
mod cosim_joints;
mod deterministic_packaging;
mod every_scene_packages;
mod explain;
mod fmi3_master;
mod generated_docs;
mod hostile_arguments;
mod hostile_binaries;
mod hostile_fmi3_fmus;
mod hostile_fmus;
mod hostile_named_files;
mod hostile_outputs;
mod hostile_scenes_show_no_files;
mod model_variables;
mod modes_cli;
mod platform_binaries;
mod random_call_sequences;
mod scene_errors;
mod simulate_shows_warnings;
mod slave_runs_c1;
