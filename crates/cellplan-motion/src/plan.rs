//! Collision-free joint-space path planning (filled in by the planning work).
