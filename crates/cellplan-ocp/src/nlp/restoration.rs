//! The feasibility restoration phase (placeholder until written).
