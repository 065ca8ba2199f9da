//! The 3D formats, apart from the service: what a 3D model of tiles is made of ([`model`]: ground
//! quads, their bordered tile images, `relief`), the documents built from it ([`assets`]: binary
//! GLB, glTF JSON, X3D) and the OGC 3D Tiles tileset and subtrees that index them ([`tileset`]).
//! The HTTP handlers (`http/models.rs`, `http/tiles3d.rs`) parse requests into these and
//! [`crate::output::Output`] encodes them; `textile render -o *.glb` builds the same.

pub mod assets;
pub mod model;
pub mod tileset;
