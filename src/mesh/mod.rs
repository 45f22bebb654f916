//! Triangle meshes as they leave the sweeps: measures of any size ([`measure`]: volume,
//! area, edge manifoldness and winding) in time linear in the faces, the solid a closed mesh
//! bounds ([`closed`]) and the pairs of faces that cross ([`intersect`]).

pub mod closed;
pub mod intersect;
pub mod measure;
