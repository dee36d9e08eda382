//! The page's statistics: the `tests` of an experiment's or a sweep's
//! `summary.json` (computed once, by [`crate::compare::tests`], when the
//! experiment finished), rendered as tables in the page itself, so that
//! they read without the script.

use std::fmt::Write as _;

use super::escape_html;
use crate::compare::{digits, p_text};
use crate::rundir::Tests;

/// The section `Statistics` for `t`: per stage and measure, each group's
/// median with its bootstrap 95% interval and, with two groups or more,
/// each pair's Mann-Whitney U test (p-value, Holm's with more than two
/// groups) and Vargha-Delaney A12. Empty without measures.
pub fn section(t: &Tests) -> String {
    if t.measures.is_empty() {
        return String::new();
    }
    let mut h = String::new();
    h.push_str(
        "<section id=\"sec-stats\" aria-labelledby=\"h-stats\">\n<h2 id=\"h-stats\">Statistics</h2>\n",
    );
    let groups: Vec<String> = t
        .groups
        .iter()
        .enumerate()
        .map(|(i, g)| format!("{} <code>{}</code>", i + 1, escape_html(g)))
        .collect();
    let _ = writeln!(
        h,
        "<p class=\"muted\" id=\"stats-note\">{}: {}. Figures: {}.</p>",
        if t.groups.len() == 1 { "Group" } else { "Groups (numbered in the pairs)" },
        groups.join(", "),
        escape_html(&t.method)
    );
    if t.groups.len() > 2 {
        let _ = writeln!(
            h,
            "<p id=\"stats-holm\">With {} groups, each measure's {} p-values are Holm-corrected (column Holm p); read those.</p>",
            t.groups.len(),
            t.groups.len() * (t.groups.len() - 1) / 2
        );
    }
    h.push_str("<table id=\"stats-medians\" class=\"grid\">\n<tr><th>stage</th><th>measure</th>");
    for (i, g) in t.groups.iter().enumerate() {
        let _ = write!(h, "<th title=\"{}\">{} median [95% interval] (seeds)</th>", escape_html(g), i + 1);
    }
    h.push_str("</tr>\n");
    for m in &t.measures {
        let d = digits(&m.measure);
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{}</td>",
            escape_html(&m.stage),
            escape_html(&m.measure.replace('_', " "))
        );
        for g in &m.groups {
            let text = match (g.median, g.interval) {
                (Some(x), Some(ci)) => format!("{x:.d$} [{:.d$}, {:.d$}] ({})", ci.low, ci.high, g.seeds),
                (Some(x), None) => format!("{x:.d$} ({})", g.seeds),
                _ => "–".to_string(),
            };
            let _ = write!(h, "<td class=\"num\">{text}</td>");
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</table>\n");
    if t.groups.len() > 1 {
        h.push_str("<table id=\"stats-tests\" class=\"grid\">\n<tr><th>stage</th><th>measure</th><th>pair</th><th>U</th><th>p-value</th>");
        if t.holm {
            h.push_str("<th>Holm p</th>");
        }
        h.push_str("<th>A12</th><th>size</th><th>test</th></tr>\n");
        for m in &t.measures {
            for p in &m.pairs {
                let _ = write!(
                    h,
                    "<tr><td>{}</td><td>{}</td><td>{} vs {}</td>",
                    escape_html(&m.stage),
                    escape_html(&m.measure.replace('_', " ")),
                    p.a,
                    p.b
                );
                match (p.u, p.p_value, p.a12, p.size, p.method) {
                    (Some(u), Some(pv), Some(a12), Some(size), Some(method)) => {
                        let _ = write!(h, "<td class=\"num\">{u}</td><td class=\"num\">{}</td>", p_text(pv));
                        if t.holm {
                            let _ = write!(
                                h,
                                "<td class=\"num\">{}</td>",
                                p.p_holm.map_or("–".to_string(), p_text)
                            );
                        }
                        let _ = write!(
                            h,
                            "<td class=\"num\">{a12:.3}</td><td>{}</td><td>{}</td>",
                            size.words(),
                            method.words()
                        );
                    }
                    _ => {
                        let span = if t.holm { 6 } else { 5 };
                        let why = p.no_test.as_deref().unwrap_or("no values");
                        let _ = write!(h, "<td colspan=\"{span}\">no test: {}</td>", escape_html(why));
                    }
                }
                h.push_str("</tr>\n");
            }
        }
        h.push_str("</table>\n");
    }
    h.push_str("</section>\n");
    h
}
