//! The comparison of groups on fixed values (the p-values are SciPy's, see
//! `stats/tests.rs` for the script: `ten_vs_ten`, `textbook_shier`).

use super::*;
use crate::stats::{Interval, Magnitude, Method};

fn group(name: &str, chosen: &[f64]) -> (String, Vec<StageMeasures>) {
    let m = StageMeasures {
        stage: "first".into(),
        kind: "evolve",
        measures: vec![("chosen_best", chosen.to_vec())],
    };
    (name.to_string(), vec![m])
}

const RECURRENT: [f64; 10] = [0.61, 0.64, 0.58, 0.70, 0.66, 0.59, 0.72, 0.63, 0.68, 0.65];
const FEED_FORWARD: [f64; 10] = [0.97, 0.95, 0.60, 0.99, 0.93, 0.96, 0.91, 0.98, 0.94, 0.62];

#[test]
fn two_groups_get_scipys_test_and_no_holm() {
    let t = tests(&[group("recurrent", &RECURRENT), group("feed-forward", &FEED_FORWARD)]);
    assert!(!t.holm);
    assert_eq!(t.measures.len(), 1);
    let m = &t.measures[0];
    assert_eq!((m.stage.as_str(), m.measure.as_str()), ("first", "chosen_best"));
    assert_eq!(m.groups[0].seeds, 10);
    assert_eq!(m.groups[0].median, Some(0.645));
    let p = &m.pairs[0];
    assert_eq!((p.a, p.b, p.u), (1, 2, Some(15.0)));
    assert!((p.p_value.unwrap() - 0.009108496398030965).abs() < 1e-14, "{p:?}");
    assert_eq!(p.a12, Some(0.15));
    assert_eq!(p.size, Some(Magnitude::Large));
    assert_eq!(p.method, Some(Method::Normal));
    assert_eq!(p.p_holm, None);
    let json = serde_json::to_value(&t).unwrap();
    let pair = &json["measures"][0]["pairs"][0];
    assert!(pair["p_value"].is_number() && pair["a12"].is_number() && pair.get("p_holm").is_none(), "{json}");
    let md = markdown(&t, "## Tests");
    assert!(md.contains("| first | chosen best | 1 | 10 | 0.645 ["), "{md}");
    assert!(
        md.contains("| first | chosen best |  |  |  | 1 vs 2 | 15 | 0.0091 | 0.150 | large | normal |"),
        "{md}"
    );
}

#[test]
fn more_than_two_groups_are_holm_corrected() {
    let men = [19., 22., 16., 29., 24.];
    let women = [20., 11., 17., 12.];
    let t = tests(&[group("a", &RECURRENT), group("b", &FEED_FORWARD), group("c", &RECURRENT)]);
    assert!(t.holm && t.method.contains("Holm"));
    let pairs = &t.measures[0].pairs;
    assert_eq!(pairs.iter().map(|p| (p.a, p.b)).collect::<Vec<_>>(), [(1, 2), (1, 3), (2, 3)]);
    // a = c: p = 1; a and c against b: p = 0.0091 each, times 3 and 2.
    assert_eq!(pairs[1].p_value, Some(1.0));
    assert!((pairs[0].p_holm.unwrap() - 3.0 * 0.009108496398030965).abs() < 1e-13);
    assert!((pairs[2].p_holm.unwrap() - 3.0 * 0.009108496398030965).abs() < 1e-13);
    assert_eq!(pairs[1].p_holm, Some(1.0));
    assert!(markdown(&t, "## Tests").contains("| Holm p |"));
    let t = tests(&[group("men", &men), group("women", &women)]);
    assert!((t.measures[0].pairs[0].p_value.unwrap() - 0.1111111111111111).abs() < 1e-15);
    assert_eq!(t.measures[0].pairs[0].method, Some(Method::Exact));
}

#[test]
fn a_group_of_one_seed_has_no_test_and_says_why() {
    let t = tests(&[group("many", &RECURRENT), group("one", &[0.9])]);
    let p = &t.measures[0].pairs[0];
    assert_eq!((p.p_value, p.a12), (None, None));
    assert_eq!(
        p.no_test.as_deref(),
        Some("`one` has 1 seed with a value; a test needs at least 2 seeds per side")
    );
    let md = markdown(&t, "## Tests");
    assert!(md.contains("no test: `one` has 1 seed"), "{md}");
    let json = serde_json::to_value(&t).unwrap();
    assert!(json["measures"][0]["pairs"][0]["p_value"].is_null());
}

#[test]
fn one_group_has_its_median_interval_and_no_pairs() {
    let t = tests(&[group("alone", &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])]);
    assert!(t.measures[0].pairs.is_empty());
    assert_eq!(t.measures[0].groups[0].interval, Some(Interval { low: 2.0, high: 8.0 }));
    assert!(markdown(&t, "## Medians").contains("| first | chosen best | 1 | 9 | 5.000 [2.000, 8.000] |\n"));
    assert!(!t.method.contains("Mann-Whitney"));
}
