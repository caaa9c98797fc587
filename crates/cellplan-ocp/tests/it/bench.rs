//! Reading `bench/ocp/*.json` (problem) and `*_casadi*.json` (reference solve); the format is
//! in `bench/ocp/README.md`.
use cellplan_kin::dynamics::Dynamics;
use cellplan_kin::load_urdf;
use cellplan_ocp::problem::{Move, Weights};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The repository's root: the first folder up from the crate that holds `bench/ocp` (this file
/// is also compiled into `bench/peers/ocp_ripopt`).
pub fn root() -> PathBuf {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    here.ancestors()
        .find(|d| d.join("bench/ocp").is_dir())
        .unwrap_or(here)
        .to_path_buf()
}

fn read(rel: &str) -> Value {
    let text = std::fs::read_to_string(root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"));
    serde_json::from_str(&text).unwrap()
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// The bench problems with the reference each is solved against (`bench/ocp/README.md`).
pub const CASES: [(&str, &str); 8] = [
    ("ur10_a", "casadi"),
    ("ur10_b", "casadi"),
    ("ur10_c", "casadi"),
    ("ur10_fast", "casadi"),
    ("kr210_a", "casadi"),
    ("kr210_a", "casadi_best"),
    ("kr210_b", "casadi"),
    ("kr210_b", "casadi_best"),
];

/// cellplan's solver as the bench runs it (`tol` 1e-10, at most 1000 iterations) from `x0`.
pub fn solve_ours(p: &Problem, x0: &[f64]) -> cellplan_ocp::nlp::Solution {
    cellplan_ocp::nlp::ipm::solve_from(
        &p.mv,
        x0,
        &cellplan_ocp::nlp::Options {
            tol: 1e-10,
            max_iter: 1000,
            verbose: std::env::var_os("CELLPLAN_NLP_VERBOSE").is_some(),
            ..cellplan_ocp::nlp::Options::default()
        },
    )
}

/// One bench problem: the move (its robot's dynamics live for the whole test run) and the
/// reference.
pub struct Problem {
    pub mv: Move<'static>,
    /// The reference: J, iterations and solve time of CasADi + IPOPT.
    pub casadi_j: f64,
    pub casadi_iterations: u64,
    pub casadi_solve_s: f64,
}

impl Problem {
    /// The initial guess the reference solve used: the brief's (`casadi`), or the brief's with
    /// the torques at zero (`casadi_best`, `--guess-u zero`).
    pub fn start(&self, reference: &str) -> Vec<f64> {
        let mut x = self.mv.initial_guess();
        if reference == "casadi_best" {
            let l = self.mv.layout();
            for i in 0..l.steps {
                for j in 0..l.n {
                    x[l.u(i, j)] = 0.0;
                }
            }
        }
        x
    }

    /// The relative distance of `j` to the nearest known local optimum of problem `name` (the
    /// reference's, and for the KR 210 problems the others listed in `bench/ocp/README.md`),
    /// and that optimum.
    pub fn nearest_optimum(&self, name: &str, j: f64) -> (f64, f64) {
        let mut known = vec![self.casadi_j];
        known.extend(match name {
            "kr210_a" => &[140.74409242326524, 139.440, 98.92193339037054][..],
            "kr210_b" => &[95.03052964755395, 113.166, 78.08866576533336][..],
            _ => &[][..],
        });
        known
            .iter()
            .map(|k| ((j - k).abs() / k, *k))
            .fold((f64::INFINITY, f64::NAN), |a, b| if b.0 < a.0 { b } else { a })
    }

    /// `name` as in `bench/ocp/NAME.json`; `reference` the suffix of the solution file
    /// (`casadi` or `casadi_best`).
    pub fn load(name: &str, reference: &str) -> Problem {
        let p = read(&format!("bench/ocp/{name}.json"));
        let r = read(&format!("bench/ocp/{name}_{reference}.json"));
        let packages: BTreeMap<String, PathBuf> = p["packages"]
            .as_object()
            .unwrap()
            .iter()
            .map(|(k, v)| (k.clone(), root().join(v.as_str().unwrap())))
            .collect();
        let model = load_urdf(
            &root().join(p["urdf"].as_str().unwrap()),
            &packages,
            p["tip"].as_str(),
        )
        .unwrap();
        // A handful of problems per test run: the dynamics are leaked so that the move can
        // borrow them for as long as the problem lives.
        let dynamics: &'static Dynamics = Box::leak(Box::new(Dynamics::new(&model.chain, &model.inertia)));
        let limits = &r["limits"];
        let q_bounds = model.chain.joints.iter().map(|j| [j.lower, j.upper]).collect();
        let w = &p["weights"];
        Problem {
            mv: Move {
                dynamics,
                start: floats(&p["q_start"]),
                goal: floats(&p["q_goal"]),
                steps: p["N"].as_u64().unwrap() as usize,
                q_bounds,
                v_max: floats(&limits["v_max"]),
                u_max: floats(&limits["u_max"]),
                h_bounds: [p["h_min"].as_f64().unwrap(), p["h_max"].as_f64().unwrap()],
                weights: Weights {
                    time: w["c_t"].as_f64().unwrap(),
                    effort: w["c_e"].as_f64().unwrap(),
                    velocity: w["c_v"].as_f64().unwrap(),
                },
            },
            casadi_j: r["J"].as_f64().unwrap(),
            casadi_iterations: r["iterations"].as_u64().unwrap(),
            casadi_solve_s: r["solve_wall_s"].as_f64().unwrap(),
        }
    }
}
