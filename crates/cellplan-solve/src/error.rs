//! Errors of the crate: [`ReadError`] of the instance readers in [`crate::io`], and the
//! validation errors of the problems ([`CostMatrixError`], [`GtspError`], [`VehicleError`],
//! [`MinMaxError`]) and of solutions checked against them ([`TourError`], [`CoverError`],
//! [`RoutesError`]).
use std::path::{Path, PathBuf};

/// Why an instance file could not be read. Every variant except [`ReadError::Io`] names the file,
/// the line (1-based) when one is to blame, and says what was expected.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The file could not be opened or read.
    #[error("cannot read `{}`: {source}; check that the path exists and is readable", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// The text does not follow the format (a missing keyword, a non-number, a short section).
    #[error("{}: {message}", location(.path, .line))]
    Syntax {
        /// The file (`<text>` when parsing a string).
        path: PathBuf,
        /// The 1-based line at fault, if one is.
        line: Option<usize>,
        /// What is wrong and what was expected.
        message: String,
    },
    /// Well-formed, but a feature this reader does not handle (another problem TYPE, an
    /// unsupported EDGE_WEIGHT_TYPE or EDGE_WEIGHT_FORMAT).
    #[error("{}: {message}", location(.path, .line))]
    Unsupported {
        /// The file.
        path: PathBuf,
        /// The 1-based line at fault, if one is.
        line: Option<usize>,
        /// What is not supported and what is.
        message: String,
    },
    /// Parsed, but the numbers are inconsistent (an index out of range, a node in two sets, a
    /// negative cost).
    #[error("{}: {message}", location(.path, .line))]
    Invalid {
        /// The file.
        path: PathBuf,
        /// The 1-based line at fault, if one is.
        line: Option<usize>,
        /// What is inconsistent and what would be valid.
        message: String,
    },
}

impl ReadError {
    /// The file the error is about.
    pub fn path(&self) -> &Path {
        match self {
            ReadError::Io { path, .. }
            | ReadError::Syntax { path, .. }
            | ReadError::Unsupported { path, .. }
            | ReadError::Invalid { path, .. } => path,
        }
    }

    /// The 1-based line at fault, when one is.
    pub fn line(&self) -> Option<usize> {
        match self {
            ReadError::Io { .. } => None,
            ReadError::Syntax { line, .. }
            | ReadError::Unsupported { line, .. }
            | ReadError::Invalid { line, .. } => *line,
        }
    }
}

impl ReadError {
    /// What is wrong, without the file and line (for callers that show those themselves).
    pub fn detail(&self) -> String {
        match self {
            ReadError::Io { source, .. } => format!("cannot read the file: {source}"),
            ReadError::Syntax { message, .. }
            | ReadError::Unsupported { message, .. }
            | ReadError::Invalid { message, .. } => message.clone(),
        }
    }
}

fn location(path: &Path, line: &Option<usize>) -> String {
    match line {
        Some(l) => format!("{}:{l}", path.display()),
        None => path.display().to_string(),
    }
}

/// Why [`crate::CostMatrix::new`] refused its data.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CostMatrixError {
    /// `n * n` does not fit in a `usize`.
    #[error("{n} nodes overflow n*n")]
    Overflow {
        /// Number of nodes.
        n: usize,
    },
    /// The data is not `n * n` entries.
    #[error("a cost matrix of {n} nodes needs {want} entries (n*n), got {got}")]
    Size {
        /// Number of nodes.
        n: usize,
        /// `n * n`.
        want: usize,
        /// Entries given.
        got: usize,
    },
    /// An entry is negative or not finite.
    #[error("cost ({row}, {col}) is {value}; costs must be finite and non-negative")]
    Entry {
        /// Its row.
        row: usize,
        /// Its column.
        col: usize,
        /// The value.
        value: f64,
    },
}

/// Which depot of a [`crate::Gtsp`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Depot {
    /// Where the tour starts.
    Start,
    /// Where the tour ends.
    End,
}

impl std::fmt::Display for Depot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Depot::Start => "start",
            Depot::End => "end",
        })
    }
}

/// Why [`crate::Gtsp::new`], [`crate::Gtsp::with_depots`] or [`crate::Gtsp::with_service`]
/// refused an instance.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum GtspError {
    /// A cluster has no node.
    #[error("cluster {cluster} is empty; every cluster needs at least one node")]
    EmptyCluster {
        /// The cluster.
        cluster: usize,
    },
    /// A cluster names a node beyond the cost matrix.
    #[error("cluster {cluster} names node {node}, but the cost matrix has only {nodes} nodes (0..{nodes})")]
    NodeOutOfRange {
        /// The cluster.
        cluster: usize,
        /// The node.
        node: usize,
        /// Nodes of the cost matrix.
        nodes: usize,
    },
    /// A node is in two clusters (or twice in one).
    #[error("node {node} is in cluster {first} and again in cluster {second}; clusters must be disjoint")]
    SharedNode {
        /// The node.
        node: usize,
        /// The cluster it is in first.
        first: usize,
        /// The cluster it is in again.
        second: usize,
    },
    /// An end depot without a start depot.
    #[error("an end depot needs a start depot; give both, or only a start to return to it")]
    EndWithoutStart,
    /// A depot beyond the cost matrix.
    #[error("{which} depot {depot} is out of range; the cost matrix has {nodes} nodes")]
    DepotOutOfRange {
        /// Which depot.
        which: Depot,
        /// Its node.
        depot: usize,
        /// Nodes of the cost matrix.
        nodes: usize,
    },
    /// A depot that is in a cluster.
    #[error("{which} depot {depot} is in cluster {cluster}; depots must not belong to a cluster")]
    DepotInCluster {
        /// Which depot.
        which: Depot,
        /// Its node.
        depot: usize,
        /// The cluster.
        cluster: usize,
    },
    /// Not one service time per node.
    #[error("{given} service times given for {nodes} nodes; give one per node")]
    ServiceCount {
        /// Service times given.
        given: usize,
        /// Nodes of the cost matrix.
        nodes: usize,
    },
    /// A service time that is negative or not finite.
    #[error("service time of node {node} is {value}; it must be finite and non-negative")]
    ServiceValue {
        /// The node.
        node: usize,
        /// The value.
        value: f64,
    },
}

/// Why [`crate::Gtsp::check`] refused a tour.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum TourError {
    /// The tour names a node beyond the instance.
    #[error("tour position {position} is node {node}, out of range (the instance has {nodes} nodes)")]
    OutOfRange {
        /// Position in the tour.
        position: usize,
        /// The node.
        node: usize,
        /// Nodes of the instance.
        nodes: usize,
    },
    /// The tour visits a node of no cluster (a depot).
    #[error("tour position {position} is node {node}, which is in no cluster")]
    NoCluster {
        /// Position in the tour.
        position: usize,
        /// The node.
        node: usize,
    },
    /// A cluster is visited twice.
    #[error(
        "cluster {cluster} is visited twice: node {first_node} at position {first_position} and node {node} at position {position}"
    )]
    ClusterTwice {
        /// The cluster.
        cluster: usize,
        /// The node of the first visit.
        first_node: usize,
        /// Position of the first visit.
        first_position: usize,
        /// The node of the second visit.
        node: usize,
        /// Position of the second visit.
        position: usize,
    },
    /// A cluster is not visited.
    #[error("cluster {cluster} is not visited")]
    ClusterMissing {
        /// The cluster.
        cluster: usize,
    },
}

/// Why [`crate::SetCover::cover_cost`] refused a choice of columns.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum CoverError {
    /// A column beyond the instance.
    #[error("column {column} is out of range (the instance has {columns} columns)")]
    ColumnOutOfRange {
        /// The column.
        column: usize,
        /// Columns of the instance.
        columns: usize,
    },
    /// A row no chosen column covers.
    #[error("row {row} is not covered")]
    Uncovered {
        /// The row.
        row: usize,
    },
}

/// Why [`crate::minmax::Vehicle::new`] refused a vehicle.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum VehicleError {
    /// The depot is beyond the vehicle's cost matrix.
    #[error("depot {depot} is out of range ({nodes} nodes)")]
    DepotOutOfRange {
        /// The depot.
        depot: usize,
        /// Nodes of the vehicle's cost matrix.
        nodes: usize,
    },
    /// A task's alternative is beyond the vehicle's cost matrix.
    #[error("task {task} names node {node}, out of range ({nodes} nodes)")]
    NodeOutOfRange {
        /// The task.
        task: usize,
        /// The node.
        node: usize,
        /// Nodes of the vehicle's cost matrix.
        nodes: usize,
    },
    /// A task names the depot as an alternative.
    #[error("task {task} names the depot {depot} as an alternative")]
    DepotAsAlternative {
        /// The task.
        task: usize,
        /// The depot.
        depot: usize,
    },
    /// A node serves two tasks (or is listed twice).
    #[error("node {node} serves task {first} and again task {second}")]
    SharedNode {
        /// The node.
        node: usize,
        /// The task it serves first.
        first: usize,
        /// The task it serves again.
        second: usize,
    },
}

/// Why [`crate::minmax::MinMaxProblem::new`] (or `validate`) refused a problem.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MinMaxError {
    /// Not one service time per task.
    #[error("{given} service times for {tasks} tasks")]
    ServiceCount {
        /// Service times given.
        given: usize,
        /// Tasks.
        tasks: usize,
    },
    /// A service time that is negative or not finite.
    #[error("service time of task {task} is {value}")]
    ServiceValue {
        /// The task.
        task: usize,
        /// The value.
        value: f64,
    },
    /// A balance limit that is negative or not finite.
    #[error("balance limit {value} must be finite and non-negative")]
    BalanceLimit {
        /// The value.
        value: f64,
    },
    /// A vehicle without one alternative list per task.
    #[error("vehicle {vehicle} has {lists} alternative lists for {tasks} tasks")]
    AlternativeLists {
        /// The vehicle.
        vehicle: usize,
        /// Its alternative lists.
        lists: usize,
        /// Tasks.
        tasks: usize,
    },
    /// A vehicle that is invalid on its own.
    #[error("vehicle {vehicle}: {error}")]
    Vehicle {
        /// The vehicle.
        vehicle: usize,
        /// What is wrong with it (shown in this error's message, so not a `source`).
        error: VehicleError,
    },
    /// A task no vehicle can do.
    #[error("no vehicle can do task {task}")]
    Undoable {
        /// The task.
        task: usize,
    },
    /// The caps add up to fewer than the tasks.
    #[error("total cap {cap} is below the {tasks} tasks")]
    TotalCap {
        /// The sum of the caps.
        cap: usize,
        /// Tasks.
        tasks: usize,
    },
    /// No assignment of every task within the caps.
    #[error("the caps admit no assignment of every task (stuck at task {task})")]
    NoAssignment {
        /// The first task no assignment can place.
        task: usize,
    },
}

/// Why [`crate::minmax::Routes::check`] refused routes.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum RoutesError {
    /// Not one tour per vehicle.
    #[error("{tours} tours for {vehicles} vehicles")]
    TourCount {
        /// Tours given.
        tours: usize,
        /// Vehicles.
        vehicles: usize,
    },
    /// A vehicle with more tasks than its cap.
    #[error("vehicle {vehicle} has {tasks} tasks, over its cap {cap}")]
    OverCap {
        /// The vehicle.
        vehicle: usize,
        /// Its tasks.
        tasks: usize,
        /// Its cap.
        cap: usize,
    },
    /// A visit to a task beyond the problem.
    #[error("vehicle {vehicle} visits task {task}, out of range")]
    TaskOutOfRange {
        /// The vehicle.
        vehicle: usize,
        /// The task.
        task: usize,
    },
    /// A task done at a node that is not one of the vehicle's alternatives for it.
    #[error("vehicle {vehicle} does task {task} at node {node}, not one of its alternatives")]
    NotAlternative {
        /// The vehicle.
        vehicle: usize,
        /// The task.
        task: usize,
        /// The node.
        node: usize,
    },
    /// A task done twice.
    #[error("task {task} is done by vehicle {first} and again by {second}")]
    DoneTwice {
        /// The task.
        task: usize,
        /// The vehicle that does it first.
        first: usize,
        /// The vehicle that does it again.
        second: usize,
    },
    /// A task not done.
    #[error("task {task} is not done")]
    NotDone {
        /// The task.
        task: usize,
    },
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The messages are those the `String` errors had.
    #[test]
    fn validation_messages() {
        let cases: [(Box<dyn std::error::Error>, &str); 7] = [
            (
                Box::new(CostMatrixError::Entry {
                    row: 1,
                    col: 0,
                    value: -1.0,
                }),
                "cost (1, 0) is -1; costs must be finite and non-negative",
            ),
            (
                Box::new(GtspError::DepotInCluster {
                    which: Depot::End,
                    depot: 2,
                    cluster: 1,
                }),
                "end depot 2 is in cluster 1; depots must not belong to a cluster",
            ),
            (
                Box::new(TourError::ClusterTwice {
                    cluster: 0,
                    first_node: 0,
                    first_position: 0,
                    node: 1,
                    position: 1,
                }),
                "cluster 0 is visited twice: node 0 at position 0 and node 1 at position 1",
            ),
            (Box::new(CoverError::Uncovered { row: 1 }), "row 1 is not covered"),
            (
                Box::new(MinMaxError::Vehicle {
                    vehicle: 1,
                    error: VehicleError::DepotOutOfRange { depot: 5, nodes: 3 },
                }),
                "vehicle 1: depot 5 is out of range (3 nodes)",
            ),
            (
                Box::new(MinMaxError::NoAssignment { task: 1 }),
                "the caps admit no assignment of every task (stuck at task 1)",
            ),
            (
                Box::new(RoutesError::DoneTwice {
                    task: 1,
                    first: 1,
                    second: 1,
                }),
                "task 1 is done by vehicle 1 and again by 1",
            ),
        ];
        for (e, text) in cases {
            assert_eq!(e.to_string(), text);
        }
    }
}
