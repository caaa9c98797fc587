//! `cellplan gen tasks` and the drawings of `check --svg`.
use super::*;

#[test]
fn gen_tasks_is_deterministic_and_valid() {
    let dir = scratch("gen");
    let out_a = dir.join("a.csv");
    let out_b = dir.join("b.csv");
    for out in [&out_a, &out_b] {
        let o = cellplan(
            &[
                "gen",
                "tasks",
                "--mesh",
                "data/parts/body-in-white/car5.obj",
                "--count",
                "12",
                "--seed",
                "5",
                "--region",
                "x=0..",
                "--facing",
                "+x",
                "--out",
                out.to_str().unwrap(),
            ],
            &dir,
        );
        assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let a = std::fs::read_to_string(&out_a).unwrap();
    assert_eq!(a, std::fs::read_to_string(&out_b).unwrap());
    let tasks = cellplan_model::tasks::parse_tasks(&out_a, &a, 1.0, 1.0, &[]).unwrap();
    assert_eq!(tasks.len(), 12);
    for t in &tasks {
        assert!(t.position.x >= 0.0);
        assert!(t.normal.x >= 0.5 - 1e-6, "{t:?}");
    }
}

#[test]
fn svg_draws_every_task() {
    let dir = scratch("svg");
    small_cell(&dir);
    let svg = dir.join("cell.svg");
    let out = cellplan(
        &[
            "check",
            dir.join("cell.toml").to_str().unwrap(),
            "--svg",
            svg.to_str().unwrap(),
        ],
        &dir,
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.trim_end().ends_with("</svg>"));
    for t in ["A", "B", "C"] {
        // Once per view.
        assert_eq!(
            text.matches(&format!("<title>{t}</title>")).count(),
            2,
            "task {t}"
        );
    }
    assert!(text.contains("<title>R1</title>") && text.contains("<title>part</title>"));
}

#[test]
fn example_task_lists_are_what_their_cell_files_say() {
    let dir = scratch("regen");
    for (name, count) in [("autobody-4r", "45"), ("autobody-2r", "20")] {
        let out = dir.join(format!("{name}.csv"));
        let o = cellplan(
            &[
                "gen",
                "tasks",
                "--mesh",
                "data/parts/body-in-white/car5.obj",
                "--count",
                count,
                "--seed",
                "2",
                "--region",
                "x=0..",
                "--facing",
                "+x",
                "--max-angle",
                "80",
                "--translate",
                "0,-2212,400",
                "-o",
                out.to_str().unwrap(),
            ],
            &dir,
        );
        assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
        let committed = std::fs::read_to_string(root().join(format!("examples/{name}/tasks.csv"))).unwrap();
        assert_eq!(
            std::fs::read_to_string(&out).unwrap(),
            committed,
            "{name}: regenerate with the command in its cell.toml"
        );
    }
}
