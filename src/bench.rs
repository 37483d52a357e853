//! `simlod bench`: the paper's Table 1 unit (cost per creature per 1/30 s of motion) and
//! figure 7's question (how many creatures hold 30 frames a second), headless.

use crate::config::SimConfig;

pub fn run(_config: &SimConfig, _quick: bool, _json: bool) {}
