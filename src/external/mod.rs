//! Grading contact codes this project did not write: [`export`] writes a scene's
//! manufactured problem on a mesh family as files any code can solve (meshes, physics,
//! loads); [`grade`] reads the solutions back and measures them with the same error
//! integrals and rate verdicts as the studies, beside this project's two cones.

pub mod checks;
pub mod codes;
pub mod export;
pub mod family;
pub mod grade;
pub mod grade_report;
pub mod judge_file;
pub mod mesh_in;
pub mod problem;
mod readme;
