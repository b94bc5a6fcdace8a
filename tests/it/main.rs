//! orthosim integration tests: one test binary (one link of Bevy), one module per topic.

mod anchorage;
mod appliance;
mod bite;
mod bone;
mod cli;
mod collision;
mod docs;
mod ecs;
mod fuzz;
mod geometry_props;
mod import;
mod labelled;
mod layers;
mod mesh_files;
mod movement;
mod occlusion_measures;
mod oracle;
mod parry_support;
mod pdl;
mod plan;
mod roots;
mod scans;
mod schedule;
mod stress;
mod teeth;
mod window;
