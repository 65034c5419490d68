//! One integration-test binary; one module per area.
mod av2;
mod c3_consistency;
mod import_rules;
mod kb_bench;
mod kitti;
mod outcomes;
mod simulator_eval;
mod workspace;
