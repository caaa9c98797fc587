use super::*;

const SMALL: &str = "NAME : small\nTYPE : TSP\nDIMENSION : 3\nEDGE_WEIGHT_TYPE : EUC_2D\n\
    NODE_COORD_SECTION\n1 0 0\n2 3 4\n3 0 1.4\nEOF\n";

#[test]
fn euc_2d_rounds() {
    let t = parse_tsplib(SMALL).unwrap();
    assert_eq!(t.name, "small");
    assert_eq!(t.costs.get(0, 1), 5.0);
    assert_eq!(t.costs.get(0, 2), 1.0);
    assert_eq!(t.costs.get(1, 1), 0.0);
}

#[test]
fn explicit_formats_agree() {
    let full = "0 1 2\n1 0 3\n2 3 0";
    let forms = [
        ("FULL_MATRIX", full),
        ("UPPER_ROW", "1 2 3"),
        ("LOWER_ROW", "1 2 3"),
        ("UPPER_DIAG_ROW", "0 1 2 0 3 0"),
        ("LOWER_DIAG_ROW", "0 1 0 2 3 0"),
    ];
    for (f, body) in forms {
        let text = format!(
            "TYPE: TSP\nDIMENSION: 3\nEDGE_WEIGHT_TYPE: EXPLICIT\nEDGE_WEIGHT_FORMAT: {f}\nEDGE_WEIGHT_SECTION\n{body}\nEOF\n"
        );
        let t = parse_tsplib(&text).unwrap_or_else(|e| panic!("{f}: {e}"));
        assert_eq!(t.costs.get(0, 1), 1.0, "{f}");
        assert_eq!(t.costs.get(2, 0), 2.0, "{f}");
        assert_eq!(t.costs.get(1, 2), 3.0, "{f}");
    }
}

#[test]
fn att_and_ceil_rules() {
    let t =
        parse_tsplib("TYPE: TSP\nDIMENSION: 2\nEDGE_WEIGHT_TYPE: ATT\nNODE_COORD_SECTION\n1 0 0\n2 10 0\n")
            .unwrap();
    // r = sqrt(100/10) = 3.162..., nint = 3 < r, so 4.
    assert_eq!(t.costs.get(0, 1), 4.0);
    let t = parse_tsplib(
        "TYPE: TSP\nDIMENSION: 2\nEDGE_WEIGHT_TYPE: CEIL_2D\nNODE_COORD_SECTION\n1 0 0\n2 1 1\n",
    )
    .unwrap();
    assert_eq!(t.costs.get(0, 1), 2.0);
}

#[test]
fn optima_file_format() {
    let m = parse_optima("a280 : 2579\ndsj1000 : 18660188 (CEIL_2D)\n\n").unwrap();
    assert_eq!(m["a280"], 2579.0);
    assert_eq!(m["dsj1000"], 18660188.0);
    let e = parse_optima("a280 2579\n").unwrap_err();
    assert_eq!(e.line(), Some(1));
}

#[test]
fn errors_name_line_and_expectation() {
    let e = parse_tsplib(&SMALL.replace("EUC_2D", "EUC_3D")).unwrap_err();
    assert!(matches!(e, ReadError::Unsupported { line: Some(4), .. }), "{e}");
    assert!(
        e.to_string().contains("EUC_3D") && e.to_string().contains("EUC_2D"),
        "{e}"
    );

    let e = parse_tsplib(&SMALL.replace("DIMENSION : 3\n", "")).unwrap_err();
    assert!(e.to_string().contains("DIMENSION"), "{e}");
    assert!(matches!(e, ReadError::Syntax { line: Some(4), .. }), "{e}");

    let e = parse_tsplib(&SMALL.replace("2 3 4", "2 3 x4")).unwrap_err();
    assert!(matches!(e, ReadError::Syntax { line: Some(7), .. }), "{e}");
    assert!(
        e.to_string().contains("`x4`") && e.to_string().contains("y coordinate"),
        "{e}"
    );

    let e = parse_tsplib(&SMALL.replace("3 0 1.4\n", "")).unwrap_err();
    assert!(matches!(e, ReadError::Syntax { line: Some(8), .. }), "{e}");
    assert!(e.to_string().contains("2 of 3"), "{e}");

    let e = parse_tsplib(&SMALL.replace("3 0 1.4\nEOF\n", "")).unwrap_err();
    assert!(matches!(e, ReadError::Syntax { line: None, .. }), "{e}");

    let e = parse_tsplib(&SMALL.replace("TYPE : TSP", "TYPE : ATSP")).unwrap_err();
    assert!(matches!(e, ReadError::Unsupported { line: Some(2), .. }), "{e}");

    let e = parse_tsplib(&SMALL.replace("NAME", "NAMX")).unwrap_err();
    assert!(e.to_string().contains("unknown keyword"), "{e}");

    let e = parse_tsplib(&SMALL.replace("3 0 1.4", "4 0 1.4")).unwrap_err();
    assert!(matches!(e, ReadError::Invalid { line: Some(8), .. }), "{e}");
}

#[test]
fn garbage_does_not_panic() {
    for text in [
        "",
        "EOF",
        ":",
        "DIMENSION: -3",
        "DIMENSION: 2\nEDGE_WEIGHT_SECTION\n1",
        "\u{0}\u{1}",
    ] {
        assert!(parse_tsplib(text).is_err(), "{text:?}");
    }
}
