//! Integration tests of cellplan-ocp: the interior-point solver on the DMOC problems of
//! `bench/ocp/` against the CasADi + IPOPT optima recorded there.
mod bench;
mod hessian_time;
#[cfg(feature = "ipopt")]
mod ipopt_bench;
mod solve_bench;
