//! pushval's integration tests, one module per topic. Physics tests run in
//! the optimised test profile (see the README's test command).

mod adapters;
mod adaptive;
mod anywhere;
mod architecture;
mod assumptions;
mod bad_input;
mod cli;
mod common;
mod control;
mod corpus;
mod engines;
mod fit;
mod gate;
mod kappa;
mod laws;
mod manifest;
mod outside;
mod power;
mod properties;
mod readme;
mod release;
mod report;
mod scenarios;
mod sessions;
mod sessions_parity;
mod slide;
mod stress;
mod study;
mod track;
mod trajectory_format;
