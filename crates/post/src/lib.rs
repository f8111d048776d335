//! The kinpost post-processor as a library.
//!
//! CL data (NX CLSF / APT) is read as a stream of statements
//! ([`cl`]), every tool pose is solved through the machine's kinematic chain
//! ([`machine`]), one solution per point is chosen ([`plan`]), the blocks are
//! written in a controller's dialect ([`nc`]), and every block, with its
//! values exactly as written, is run back through the forward kinematics and
//! compared with its CL pose ([`check`]).
//!
//! ```
//! use kinpost_post::{post, PostOptions};
//! let machine = kinpost_post::machine::builtin::load("mts1600").unwrap().unwrap();
//! let dialect = kinpost_post::nc::Dialect::builtin("csv").unwrap();
//! let cl = "RAPID\nGOTO/-416,70.5,16.53,0,0,1\nFEDRAT/MMPM,250\nGOTO/-416,70.3931,11.3684\n";
//! let mut nc = Vec::new();
//! let options = PostOptions { cl_file: "flat.cls".into(), ..Default::default() };
//! let summary = post(cl.as_bytes(), &machine, &dialect, &mut nc, &options).unwrap();
//! assert_eq!(summary.blocks, 2);
//! assert!(summary.max_position_error_mm < summary.tolerance_mm);
//! ```

pub mod check;
mod emit;
mod machine_templates;
mod path;
mod post;
mod pressure;
mod solve;
pub mod summary;

pub use kinpost_cl as cl;
pub use kinpost_diag as diag;
pub use kinpost_machine as machine;
pub use kinpost_nc as nc;
pub use kinpost_plan as plan;
pub use machine_templates::check_machine_templates;
pub use post::{
    DEFAULT_LINTOL_MM, DEFAULT_RETRACT_MM, DEFAULT_SINGULAR_CONE_DEG, FeedMode, PLANNER_LAG,
    PlannerMode, PostError, PostOptions, axis_specs, post,
};
pub use summary::Summary;
