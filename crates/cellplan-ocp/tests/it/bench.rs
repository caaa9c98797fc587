//! Reading `bench/ocp/*.json` (problem) and `*_casadi*.json` (reference solve); the format is
//! in `bench/ocp/README.md`.
use cellplan_kin::dynamics::Dynamics;
use cellplan_kin::load_urdf;
use cellplan_ocp::problem::{Move, Weights};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
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
