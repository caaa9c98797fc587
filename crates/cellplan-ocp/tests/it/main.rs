//! Integration tests of cellplan-ocp: the interior-point solver on the DMOC problems of
//! `bench/ocp/` against the CasADi + IPOPT optima recorded there.
mod bench;
mod hessian_time;
mod solve_bench;
