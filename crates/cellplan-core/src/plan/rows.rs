//! Robots in rows and the line they run along: where ours draws its strips
//! ([`super::PlanSettings::sweep`]) and how far along it each task lies.
use cellplan_model::Cell;

/// The robots in rows, and the line the rows run along (`None` for fewer than two robots or
/// bases on one spot). Robots facing the same way (their bases' x axes in the floor plane
/// within 45°, in cell order) make a row, as robots on one side of a part do; the line is the
/// principal axis of the bases about their rows' centres (rows facing each other across a part
/// run along it), or, when every row is one robot, of all the bases.
pub fn robot_rows(cell: &Cell) -> Option<([f64; 2], Vec<Vec<usize>>)> {
    if cell.robots.len() < 2 {
        return None;
    }
    let facing = |r: usize| {
        let x = cell.robots[r].base.rotation * glam::DVec3::X;
        glam::DVec2::new(x.x, x.y).normalize_or_zero()
    };
    let mut rows: Vec<Vec<usize>> = Vec::new();
    for r in 0..cell.robots.len() {
        match rows
            .iter_mut()
            .find(|row| facing(row[0]).dot(facing(r)) > std::f64::consts::FRAC_1_SQRT_2)
        {
            Some(row) => row.push(r),
            None => rows.push(vec![r]),
        }
    }
    let base = |r: usize| {
        glam::DVec2::new(
            cell.robots[r].base.translation.x,
            cell.robots[r].base.translation.y,
        )
    };
    // Rows of one robot each are one row: the scatter is then about the centre of all bases.
    if rows.iter().all(|row| row.len() == 1) {
        rows = vec![(0..cell.robots.len()).collect()];
    }
    let groups = &rows;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for g in groups {
        let centre = g.iter().map(|&r| base(r)).sum::<glam::DVec2>() / g.len() as f64;
        for &r in g {
            let d = base(r) - centre;
            sxx += d.x * d.x;
            sxy += d.x * d.y;
            syy += d.y * d.y;
        }
    }
    if sxx + syy <= 1e-12 {
        return None;
    }
    // The eigenvector of the larger eigenvalue of the 2×2 scatter matrix.
    let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    Some(([angle.cos(), angle.sin()], rows))
}

/// Each task's place along `sweep` (its position projected on the direction), or none.
pub fn sweep_keys(cell: &Cell, sweep: Option<[f64; 2]>) -> Vec<f64> {
    match sweep {
        None => Vec::new(),
        Some([x, y]) => cell
            .tasks
            .iter()
            .map(|t| t.position.x * x + t.position.y * y)
            .collect(),
    }
}

/// What every robot's order must respect under `settings`: the sweep's keys
/// ([`super::PlanSettings::sweep`]) and the late tasks ([`super::PlanSettings::late`]).
pub fn order_rule(cell: &Cell, settings: &super::PlanSettings) -> super::sequence::OrderRule {
    super::sequence::OrderRule {
        sweep: sweep_keys(cell, settings.sweep),
        late: settings.late.clone(),
    }
}
