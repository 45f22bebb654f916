//! Triangle meshes as they leave the sweeps: measures of any size ([`measure`]: volume,
//! area, edge manifoldness and winding) in time linear in the faces.

pub mod closed;
pub mod measure;
