//! simlod's lab: the tools that measure and record, outside the core library.
//!
//! - [`record`]: the gait recorder, which runs a kind's rigid model at steady speeds and
//!   writes its gait table (paper 3.2);
//! - [`scene`]: the scenes they run (a scenario scaled, one kind alone, a lone creature);
//! - [`bench`](mod@bench): the cost of each level per creature per 1/30 s, and the most creatures at
//!   30 fps;
//! - [`experiments`]: Table 1 and figures 3, 4 and 7-10, and the experiments beyond the
//!   paper, with their plots and report.

#![warn(missing_docs)]

pub mod bench;
pub mod error;
pub mod experiments;
pub mod record;
pub mod scene;

pub use error::{LabError, io_error};
