//! Every integration test of fmu-beam in one test binary: one compile and one link of the
//! engine's rlib instead of one per file (issue 46 item 6: the Rust tests' compile was 2 of
//! `make test`'s minutes). Each file is a module of the name its binary had: nextest names a
//! test `integration <file>::<test>`, and `cargo test --test integration <file>::` runs one file.
//! memory_is_flat keeps a binary of its own (Cargo.toml says why).

mod common;

mod bad_input_is_refused;
mod c1_free_vibration;
mod c2_flexible_pendulum;
mod c3_slider_crank;
mod c4_spin_up;
mod concurrent_instances_share_nothing;
mod effects;
mod exact_references;
mod hard_cases_stay_stable;
mod interface_derivatives;
mod issue_12_long_do_step_drift;
mod issue_32_assembly;
mod issue_32_damping_is_the_beams;
mod issue_32_diagnosis;
mod issue_32_effects_all_means_all;
mod issue_32_modes;
mod issue_32_stiffening_3d;
mod issue_44_modes;
mod issue_45_forged_states;
mod issue_45_ranges;
mod issue_45_times;
mod issue_45_work_budget;
mod joints_and_loads;
mod jumps_create_no_energy;
mod layers;
mod parameters_as_packaged;
mod refused_calls_change_nothing;
mod scene_rules;
mod scenes_3d;
mod shape_outputs;
mod stated_accuracy_holds_when_refined;
mod tunable_loads;
