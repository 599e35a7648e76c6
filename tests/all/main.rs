//! One integration-test binary, a module per topic (mesh, tagging, dynamics, contact
//! validation, studies, bad input, regressions named after the bug they pin).
//! Physics tests state their reference and tolerance in a comment.

mod architecture;
mod bad_input;
mod cli;
mod cluster;
mod dam;
mod common;
mod contact;
mod contact_validation;
mod dam_physics;
mod dam_study;
mod dynamics;
mod foundation;
mod fuzz;
mod hardening;
mod joint_tests;
mod mesh;
mod mortar;
mod motion;
mod motion_scene;
mod outputs;
mod report;
mod reservoir;
mod rigid;
mod study;
mod tagging;
mod wedge;
mod wedge_mechanism;
