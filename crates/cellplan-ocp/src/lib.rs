//! Optimal control of robot motion (paper 002): [`dmoc`], the DMOC transcription of a robot's
//! dynamics — the forced discrete Euler–Lagrange equations of the midpoint rule and the
//! boundary conditions of the discrete Legendre transform, generic over the scalar so that
//! dual numbers give their exact derivatives — and the variational integrator they define;
//! [`problem`], one move between two rest configurations as a nonlinear program (free final
//! time, the paper's cost, exact sparse Jacobian).
#![warn(missing_docs)]

pub mod dmoc;
pub mod nlp;
pub mod problem;
pub mod taylor;
