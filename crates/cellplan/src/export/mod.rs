//! Exports of a plan for other tools: binary glTF with animation (Blender, any glTF viewer) and
//! CSV for robot post-processors.
pub mod csv;
pub mod gltf;
