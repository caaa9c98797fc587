//! What the fault-injection tests share: the crossing cell's fixed-priority plan, which the
//! verifier accepts, and the kinds of violation the verifier finds in a document.
use cellplan_core::coord::Coordination;
use cellplan_core::document as output;
use cellplan_optical::testing::{document, fixture};
use cellplan_verify::{VerifySettings, ViolationKind, verify};

/// The crossing cell coordinated by fixed priority, checked clean by the verifier.
pub fn good_plan() -> output::Plan {
    let (good, _) = document(Coordination::FixedPriority);
    assert!(verify(&fixture().cell, &good, &VerifySettings::default()).ok);
    good
}

/// The kinds of violation the verifier finds in `doc` on the crossing cell.
pub fn kinds(doc: &output::Plan) -> Vec<ViolationKind> {
    verify(&fixture().cell, doc, &VerifySettings::default())
        .violations
        .iter()
        .map(|v| v.kind)
        .collect()
}
