//! Bad inputs: every file of `tests/ui/` must fail, or compile with
//! warnings; the snapshot is the source followed by the rendered
//! diagnostics (no colour, 80 columns).
//! Inputs too big for a file are generated, and only their diagnostics kept.

use shaping_compiler::Error;

use crate::render;

#[test]
fn ui() {
    insta::glob!("../../..", "tests/ui/*.bat", |path| {
        let src = std::fs::read_to_string(path).unwrap();
        let name = path.file_name().unwrap().to_string_lossy();
        let (program, d) = shaping_compiler::check(&src, &name);
        assert!(
            !d.is_empty(),
            "{name} compiles without a diagnostic, but every file in tests/ui must have one"
        );
        // A file compiles exactly when its diagnostics are warnings only.
        assert_eq!(program.is_some(), d.error_count() == 0, "{name}");
        insta::assert_snapshot!(format!("{src}\n{}", render(&d)));
    });
}

/// Megabytes of modules: the parser's call limit gives up.
fn too_complex() -> String {
    let mut src = String::from(
        "robot r { sensor ir[8] proximity actuator wheels[2] speed }\nstage s {\n fitness per action 1\n",
    );
    src.push_str(&" module m { sense ir behavior forward }\n".repeat(200_000));
    src.push_str("}\n");
    src
}

#[test]
fn ui_generated() {
    let d = shaping_compiler::compile(&too_complex(), "too_complex.bat").unwrap_err();
    insta::assert_snapshot!("too_complex", render(&d));
}

/// The kind of an error, by an exhaustive match: a new variant fails to
/// compile here until it is added to [`KINDS`] and given a ui test.
fn kind(e: &Error) -> &'static str {
    match e {
        Error::Syntax { .. } => "Syntax",
        Error::TooComplex { .. } => "TooComplex",
        Error::LineTooLong { .. } => "LineTooLong",
        Error::TooDeep { .. } => "TooDeep",
        Error::TooLarge { .. } => "TooLarge",
        Error::Unknown { .. } => "Unknown",
        Error::Duplicate { .. } => "Duplicate",
        Error::IndexOutOfRange { .. } => "IndexOutOfRange",
        Error::BadRange { .. } => "BadRange",
        Error::Type { .. } => "Type",
        Error::Bits { .. } => "Bits",
        Error::Cycle { .. } => "Cycle",
        Error::NotSensed { .. } => "NotSensed",
        Error::UnboundedUntil { .. } => "UnboundedUntil",
        Error::MissingHardware { .. } => "MissingHardware",
        Error::Frozen { .. } => "Frozen",
        Error::Unit { .. } => "Unit",
        Error::Value { .. } => "Value",
        Error::StackTooDeep { .. } => "StackTooDeep",
        Error::Conflict { .. } => "Conflict",
        Error::SimilarName { .. } => "SimilarName",
        Error::TeamTooLarge { .. } => "TeamTooLarge",
        Error::TeamOfOne { .. } => "TeamOfOne",
        Error::RoleWithoutGenes { .. } => "RoleWithoutGenes",
        Error::OutsideRole { .. } => "OutsideRole",
        Error::EmptyRole { .. } => "EmptyRole",
        Error::RoleRobots { .. } => "RoleRobots",
        Error::RolesNotHere { .. } => "RolesNotHere",
        Error::EvolvedWithoutGenes { .. } => "EvolvedWithoutGenes",
        Error::NotASensor { .. } => "NotASensor",
        Error::NoLamp { .. } => "NoLamp",
        Error::VariantUndoesChange { .. } => "VariantUndoesChange",
        Error::PlaceOutside { .. } => "PlaceOutside",
        Error::PlaceBlocked { .. } => "PlaceBlocked",
        Error::PlaceTeam { .. } => "PlaceTeam",
        Error::PlaceAfterLife { .. } => "PlaceAfterLife",
        Error::UnknownRole { .. } => "UnknownRole",
        Error::RoleModuleExists { .. } => "RoleModuleExists",
        Error::LinkAcrossRoles { .. } => "LinkAcrossRoles",
        Error::RoleInTest { .. } => "RoleInTest",
        Error::RoleFitnessReadsOther { .. } => "RoleFitnessReadsOther",
        Error::RoleFitnessAlone { .. } => "RoleFitnessAlone",
        Error::RabRange { .. } => "RabRange",
        Error::SignalChannels { .. } => "SignalChannels",
        Error::Unheard { .. } => "Unheard",
        Error::SignalValues { .. } => "SignalValues",
        Error::RabUnused { .. } => "RabUnused",
        Error::SilencedNothing { .. } => "SilencedNothing",
    }
}

const KINDS: [&str; 48] = [
    "Syntax",
    "TooComplex",
    "LineTooLong",
    "TooDeep",
    "TooLarge",
    "Unknown",
    "Duplicate",
    "IndexOutOfRange",
    "BadRange",
    "Type",
    "Bits",
    "Cycle",
    "NotSensed",
    "UnboundedUntil",
    "MissingHardware",
    "Frozen",
    "Unit",
    "Value",
    "StackTooDeep",
    "Conflict",
    "SimilarName",
    "TeamTooLarge",
    "TeamOfOne",
    "RoleWithoutGenes",
    "OutsideRole",
    "EmptyRole",
    "RoleRobots",
    "RolesNotHere",
    "EvolvedWithoutGenes",
    "NotASensor",
    "NoLamp",
    "VariantUndoesChange",
    "PlaceOutside",
    "PlaceBlocked",
    "PlaceTeam",
    "PlaceAfterLife",
    "UnknownRole",
    "RoleModuleExists",
    "LinkAcrossRoles",
    "RoleInTest",
    "RoleFitnessReadsOther",
    "RoleFitnessAlone",
    "RabRange",
    "SignalChannels",
    "Unheard",
    "SignalValues",
    "RabUnused",
    "SilencedNothing",
];

#[test]
fn every_error_kind_has_a_ui_test() {
    let mut seen = std::collections::BTreeSet::new();
    let mut files = 0;
    for entry in std::fs::read_dir(crate::root().join("tests/ui")).unwrap() {
        let path = entry.unwrap().path();
        let src = std::fs::read_to_string(&path).unwrap();
        let (_, d) = shaping_compiler::check(&src, "ui.bat");
        seen.extend(d.errors().iter().map(kind));
        files += 1;
    }
    seen.extend(shaping_compiler::compile(&too_complex(), "ui.bat").unwrap_err().errors().iter().map(kind));
    assert!(files >= 25, "{files} ui files, at least 25 expected");
    let missing: Vec<_> = KINDS.iter().filter(|k| !seen.contains(*k)).collect();
    assert!(missing.is_empty(), "error kinds without a ui test: {missing:?}");
}

/// What `S0032` warns about (`tests/ui/variant_undoes_change.bat`): the
/// variants a stage inherits are applied after its own changes, so a
/// variant that restates the lamp keeps its lamp, undimmed.
#[test]
fn an_inherited_variant_restating_an_item_keeps_its_own() {
    let src = std::fs::read_to_string(crate::root().join("tests/ui/variant_undoes_change.bat")).unwrap();
    let (program, d) = shaping_compiler::check(&src, "variant_undoes_change.bat");
    let dimmed = &program.expect("warnings only").stages[1];
    let lamp = |w: &shaping_runtime::program::World| w.items.lamps[0].intensity;
    assert_eq!(lamp(&dimmed.world), 0.5);
    let variants: Vec<(&str, f32)> =
        dimmed.variants.as_ref().unwrap().list.iter().map(|v| (v.name.as_str(), lamp(&v.world))).collect();
    assert_eq!(variants, [("left", 1.0), ("right", 1.0), ("same", 0.5)]);
    let warned: Vec<String> = d.errors().iter().map(|e| e.to_string()).collect();
    assert_eq!(warned.len(), 2);
    assert!(warned[0].contains("`left`") && warned[1].contains("`right`"), "{warned:?}");
}
