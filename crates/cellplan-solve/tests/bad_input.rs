//! Bad input is a clean refusal: a typed error naming the file and line and what to do, never a
//! panic, an allocation sized by an unchecked count, or an unbounded read.
use std::io::Write as _;
use std::path::Path;

use cellplan_solve::ReadError;
use cellplan_solve::io::{
    MAX_DENSE_NODES, MAX_FILE_BYTES, MAX_TASKS, MAX_VEHICLES, parse_gtsplib, parse_minmax,
    parse_orlib_setcover, parse_tsplib, read_gtsplib, read_minmax, read_orlib_setcover, read_tsplib,
};

/// A valid min-max file: 2 vehicles, 2 tasks (lines 3 and 4 hold VEHICLES and TASKS, line 12
/// the first NODES).
const MINMAX: &str = "NAME: small
TYPE: MINMAX
VEHICLES: 2
TASKS: 2
SERVICE_SECTION
0.5
0.25
VEHICLE: 0
DEPOT: 0
CAP: 2
NODES: 3
FULL_MATRIX
0 1 2
1 0 1
2 1 0
ALTERNATIVES
0: 1
1: 2
VEHICLE: 1
DEPOT: 0
CAP: 1
NODES: 2
FULL_MATRIX
0 1
1 0
ALTERNATIVES
0:
1: 1
EOF
";

const TSP: &str = "NAME : small\nTYPE : TSP\nDIMENSION : 3\nEDGE_WEIGHT_TYPE : EUC_2D\n\
    NODE_COORD_SECTION\n1 0 0\n2 3 4\n3 0 1.4\nEOF\n";

const GTSP: &str = "NAME: t\nTYPE: GTSP\nDIMENSION: 3\nGTSP_SETS: 2\nEDGE_WEIGHT_TYPE: EXPLICIT\n\
    EDGE_WEIGHT_FORMAT: FULL_MATRIX\nEDGE_WEIGHT_SECTION\n0 1 2\n1 0 3\n2 3 0\n\
    GTSP_SET_SECTION:\n1 1 2 -1\n2 3 -1\nEOF\n";

const GLNS: &str = "N: 3\nM: 2\n1 1\n2 2 3\n0 1 2\n1 0 3\n2 3 0\n";

/// Asserts `e` is `Invalid` at `line` and its message holds every one of `says`.
fn invalid_at(e: &ReadError, line: usize, says: &[&str]) {
    assert!(matches!(e, ReadError::Invalid { .. }), "{e:?}");
    assert_eq!(e.line(), Some(line), "{e}");
    let shown = e.to_string();
    assert!(shown.starts_with(&format!("<text>:{line}: ")), "{shown}");
    for s in says {
        assert!(shown.contains(s), "`{s}` missing from: {shown}");
    }
}

#[test]
fn minmax_huge_counts_are_refused_before_allocating() {
    let limit = MAX_DENSE_NODES.to_string();
    let e = parse_minmax(&MINMAX.replacen("NODES: 3", "NODES: 3000000000", 1)).unwrap_err();
    invalid_at(&e, 11, &["NODES is 3000000000", &limit, "dense"]);
    let e = parse_minmax(&MINMAX.replacen("NODES: 2", "NODES: 3000000000", 1)).unwrap_err();
    invalid_at(&e, 22, &["NODES is 3000000000"]);
    let e = parse_minmax(&MINMAX.replace("VEHICLES: 2", "VEHICLES: 4000000000")).unwrap_err();
    invalid_at(&e, 3, &["VEHICLES is 4000000000", &MAX_VEHICLES.to_string()]);
    let e = parse_minmax(&MINMAX.replace("TASKS: 2", "TASKS: 4000000000")).unwrap_err();
    invalid_at(&e, 4, &["TASKS is 4000000000", &MAX_TASKS.to_string()]);
    // Beyond even u64: still the count, not "not an integer".
    let e = parse_minmax(&MINMAX.replace("TASKS: 2", "TASKS: 99999999999999999999999")).unwrap_err();
    invalid_at(&e, 4, &["TASKS is 99999999999999999999999"]);
    // Just within the limit but with one row of data: refused for the short matrix, quickly.
    let e = parse_minmax(&MINMAX.replacen("NODES: 3", &format!("NODES: {MAX_DENSE_NODES}"), 1)).unwrap_err();
    assert!(matches!(e, ReadError::Syntax { line: Some(13), .. }), "{e}");
}

#[test]
fn minmax_extra_lines_name_the_count() {
    let e = parse_minmax(&MINMAX.replacen("0.25\n", "0.25\n0.75\n", 1)).unwrap_err();
    assert!(matches!(e, ReadError::Syntax { line: Some(8), .. }), "{e}");
    assert!(e.to_string().contains("more service times than TASKS: 2"), "{e}");
    let e = parse_minmax(&MINMAX.replacen("1: 2\n", "1: 2\n2: 3\n", 1)).unwrap_err();
    assert!(matches!(e, ReadError::Syntax { line: Some(19), .. }), "{e}");
    assert!(
        e.to_string()
            .contains("vehicle 0 has more alternative lines than TASKS: 2"),
        "{e}"
    );
}

#[test]
fn tsplib_huge_dimension_is_refused_with_count_limit_and_line() {
    for huge in ["3000000000", "15001", "99999999999999999999999"] {
        let e = parse_tsplib(&TSP.replace("DIMENSION : 3", &format!("DIMENSION : {huge}"))).unwrap_err();
        invalid_at(
            &e,
            3,
            &[&format!("DIMENSION is {huge}"), &MAX_DENSE_NODES.to_string()],
        );
    }
    // An explicit matrix stated at the limit but given one weight: refused for the data, with
    // no n² reservation up front.
    let text = format!(
        "TYPE: TSP\nDIMENSION: {MAX_DENSE_NODES}\nEDGE_WEIGHT_TYPE: EXPLICIT\nEDGE_WEIGHT_FORMAT: FULL_MATRIX\nEDGE_WEIGHT_SECTION\n0\nEOF\n"
    );
    let e = parse_tsplib(&text).unwrap_err();
    assert!(matches!(e, ReadError::Syntax { line: Some(7), .. }), "{e}");
    assert!(e.to_string().contains("ends after 1 of 225000000 weights"), "{e}");
}

#[test]
fn tsplib_counts_must_agree_with_the_data() {
    let e = parse_tsplib(&TSP.replace("3 0 1.4\n", "3 0 1.4\n4 1 1\n")).unwrap_err();
    assert!(matches!(e, ReadError::Syntax { line: Some(9), .. }), "{e}");
    assert!(
        e.to_string()
            .contains("more than the 3 node lines DIMENSION states"),
        "{e}"
    );
    // A second DIMENSION would disagree with the section sized by the first.
    let e = parse_tsplib(&TSP.replace("EOF\n", "DIMENSION : 5\nEOF\n")).unwrap_err();
    assert!(matches!(e, ReadError::Syntax { line: Some(9), .. }), "{e}");
    assert!(
        e.to_string()
            .contains("DIMENSION is given twice (first on line 3"),
        "{e}"
    );
    // A format stated after the weights does not reinterpret them.
    let text = "TYPE: TSP\nDIMENSION: 3\nEDGE_WEIGHT_TYPE: EXPLICIT\nEDGE_WEIGHT_FORMAT: UPPER_ROW\n\
        EDGE_WEIGHT_SECTION\n1 2 3\nEDGE_WEIGHT_FORMAT: FULL_MATRIX\nEOF\n";
    let t = parse_tsplib(text).unwrap();
    assert_eq!(t.costs.get(1, 2), 3.0);
}

#[test]
fn gtsplib_huge_set_counts_are_refused() {
    let e = parse_gtsplib(&GTSP.replace("GTSP_SETS: 2", "GTSP_SETS: 4000000000")).unwrap_err();
    invalid_at(
        &e,
        4,
        &[
            "GTSP_SETS is 4000000000",
            &MAX_DENSE_NODES.to_string(),
            "at most one per node",
        ],
    );
    // More sets than nodes cannot be disjoint and non-empty.
    let e = parse_gtsplib(&GTSP.replace("GTSP_SETS: 2", "GTSP_SETS: 4")).unwrap_err();
    invalid_at(&e, 4, &["GTSP_SETS is 4 but DIMENSION is 3"]);
    let e = parse_gtsplib(&GLNS.replace("N: 3", "N: 3000000000")).unwrap_err();
    invalid_at(&e, 1, &["N is 3000000000", &MAX_DENSE_NODES.to_string()]);
    let e = parse_gtsplib(&GLNS.replace("M: 2", "M: 4000000000")).unwrap_err();
    invalid_at(&e, 2, &["M is 4000000000"]);
    let e = parse_gtsplib(&GLNS.replace("M: 2", "M: 4")).unwrap_err();
    invalid_at(&e, 2, &["M is 4 but there are only 3 nodes"]);
}

#[test]
fn gtsp_node_in_no_set_is_refused() {
    assert!(parse_gtsplib(GTSP).is_ok());
    let e = parse_gtsplib(&GTSP.replace("1 1 2 -1", "1 1 -1")).unwrap_err();
    invalid_at(&e, 11, &["node 2 is in no set", "1..=3 (DIMENSION)"]);
    assert!(parse_gtsplib(GLNS).is_ok());
    let e = parse_gtsplib(&GLNS.replace("2 2 3\n", "2 3\n")).unwrap_err();
    invalid_at(&e, 2, &["node 2 is in no set", "1..=3 (N)"]);
}

#[test]
fn glns_set_lines_must_not_be_truncated_silently() {
    let e = parse_gtsplib(&GLNS.replace("2 2 3\n", "2 2 -1 3\n")).unwrap_err();
    assert!(matches!(e, ReadError::Syntax { line: Some(4), .. }), "{e}");
    assert!(e.to_string().contains("`3` after the -1 that ends set 2"), "{e}");
    let e = parse_gtsplib(&GLNS.replace("1 1\n", "1\n")).unwrap_err();
    invalid_at(&e, 3, &["set 1 has no nodes"]);
    // Weight errors now name their line.
    let e = parse_gtsplib(&GLNS.replace("1 0 3", "1 x 3")).unwrap_err();
    assert!(matches!(e, ReadError::Syntax { line: Some(6), .. }), "{e}");
    assert!(e.to_string().contains("row 2, column 2"), "{e}");
}

#[test]
fn orlib_huge_sizes_are_refused_on_their_line() {
    let e = parse_orlib_setcover("4000000000 3\n1 2 3\n").unwrap_err();
    invalid_at(&e, 1, &["rows m is 4000000000", "100000000"]);
    let e = parse_orlib_setcover("2\n4000000000\n1 2 3\n").unwrap_err();
    invalid_at(&e, 2, &["columns n is 4000000000", "100000000"]);
    // Stated at 50 million columns but with two costs: refused where the data ends.
    let e = parse_orlib_setcover("1 50000000\n1 1\n").unwrap_err();
    assert!(matches!(e, ReadError::Syntax { line: Some(2), .. }), "{e}");
    assert!(e.to_string().contains("column 3 of 50000000"), "{e}");
}

fn temp_with(bytes: &[u8], name: &str) -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::File::create(&path).unwrap().write_all(bytes).unwrap();
    (dir, path)
}

#[test]
fn oversized_files_are_refused_before_reading() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.tsp");
    // Sparse: takes no disk, but its size is over the limit.
    let f = std::fs::File::create(&path).unwrap();
    f.set_len(MAX_FILE_BYTES + 1).unwrap();
    drop(f);
    for e in [
        read_tsplib(&path).unwrap_err(),
        read_gtsplib(&path).unwrap_err(),
        read_orlib_setcover(&path).unwrap_err(),
        read_minmax(&path).unwrap_err(),
    ] {
        assert!(matches!(e, ReadError::Invalid { line: None, .. }), "{e:?}");
        assert_eq!(e.path(), path.as_path());
        let shown = e.to_string();
        assert!(shown.contains("huge.tsp"), "{shown}");
        assert!(
            shown.contains(&format!("{} bytes", MAX_FILE_BYTES + 1)) && shown.contains("512 MiB"),
            "{shown}"
        );
    }
}

#[test]
fn non_utf8_files_name_the_line() {
    let mut bytes = TSP.as_bytes().to_vec();
    // A Latin-1 "é" in the comment on line 2.
    let at = TSP.find("TYPE").unwrap();
    bytes.splice(at..at, b"COMMENT : caf\xe9\n".iter().copied());
    let (_dir, path) = temp_with(&bytes, "latin1.tsp");
    let e = read_tsplib(&path).unwrap_err();
    assert!(matches!(e, ReadError::Syntax { line: Some(2), .. }), "{e:?}");
    let shown = e.to_string();
    assert!(
        shown.contains("latin1.tsp:2:") && shown.contains("not UTF-8"),
        "{shown}"
    );
}

#[test]
fn a_missing_file_is_still_an_io_error() {
    let e = read_tsplib(Path::new("/nonexistent/x.tsp")).unwrap_err();
    assert!(matches!(e, ReadError::Io { .. }), "{e}");
}

#[cfg(target_os = "linux")]
#[test]
fn dev_zero_is_refused_not_read_forever() {
    // Reads MAX_FILE_BYTES + 1 bytes, then stops.
    let e = read_minmax("/dev/zero").unwrap_err();
    assert!(matches!(e, ReadError::Invalid { line: None, .. }), "{e:?}");
    let shown = e.to_string();
    assert!(shown.starts_with("/dev/zero: "), "{shown}");
    assert!(
        shown.contains(&format!("more than {MAX_FILE_BYTES} bytes")) && shown.contains("512 MiB"),
        "{shown}"
    );
}
