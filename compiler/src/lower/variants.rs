//! `variants mean [draw N] { NAME { ITEMS } ... }`: named variants of a
//! stage's world, each the stage's world with the variant's changes (as in
//! `world changes`). A stage inherits its parent's variants, applied again
//! to its own world; its own `variants` replaces them.

use shaping_runtime::limits::MAX_VARIANTS;
use shaping_runtime::program::{Aggregate, StageRun, Variant, Variants};

use super::*;
use crate::diag::{did_you_mean, Error};
use crate::syntax::ast;

/// The variants a stage has: declared by it or inherited.
#[derive(Clone, Debug)]
pub(crate) struct VariantsSt {
    pub aggregate: Aggregate,
    pub draw: Option<u32>,
    pub decls: Vec<ast::VariantDecl>,
    /// The `variants` declaration.
    pub span: Span,
}

/// The aggregations of `variants`.
pub(crate) const AGGREGATES: [&str; 2] = ["mean", "min"];

impl Lower<'_> {
    /// The stage's own `variants` (at most one), into `st.variants`.
    pub(super) fn variants_decl(&mut self, st: &mut StageSt, decl: &ast::StageDecl) {
        let mut first: Option<Span> = None;
        for item in &decl.items {
            let ast::StageItem::Variants(v) = item else { continue };
            if let Some(f) = first {
                self.errors.push(Error::Duplicate {
                    span: v.span.into(),
                    first: f.into(),
                    what: "declaration",
                    name: "variants".into(),
                });
                continue;
            }
            first = Some(v.span);
            let aggregate = match v.aggregate.text.as_str() {
                "mean" => Some(Aggregate::Mean),
                "min" => Some(Aggregate::Min),
                other => {
                    self.errors.push(Error::Unknown {
                        span: v.aggregate.span.into(),
                        what: "aggregation of variants",
                        name: other.into(),
                        help: did_you_mean(other, AGGREGATES).or_else(|| {
                            Some("`variants mean { ... }` or `variants min { ... }`: the mean or the lowest fitness of the variants".into())
                        }),
                    });
                    None
                }
            };
            let mut seen: HashMap<&str, Span> = HashMap::new();
            for d in &v.variants {
                if let Some(f) = seen.get(d.name.text.as_str()) {
                    self.errors.push(Error::Duplicate {
                        span: d.name.span.into(),
                        first: (*f).into(),
                        what: "variant",
                        name: d.name.text.clone(),
                    });
                }
                seen.insert(&d.name.text, d.name.span);
            }
            let n = v.variants.len();
            if n == 0 {
                self.value_error(
                    v.span,
                    format!("stage `{}` declares variants but names none", decl.name.text),
                    "no variant",
                    Some("name each variant and its changes: `variants mean { left { zone cue ... } right { ... } }`".into()),
                );
            } else if n > MAX_VARIANTS {
                self.value_error(
                    v.span,
                    format!("a stage has at most {MAX_VARIANTS} variants, and this one declares {n}"),
                    "too many variants",
                    None,
                );
            }
            let draw = match &v.draw {
                None => None,
                Some(q) => match self.count_in(q, "the number of variants drawn", 1, MAX_VARIANTS as u64) {
                    Some(k) if n > 0 && k as usize > n => {
                        self.value_error(
                            q.span,
                            format!(
                                "stage `{}` draws {k} variants per generation, but declares {n}",
                                decl.name.text
                            ),
                            "more than declared",
                            Some(format!("draw at most {n}, or leave `draw` out to evaluate every variant")),
                        );
                        None
                    }
                    k => k.map(|k| k as u32),
                },
            };
            // After an error in the aggregation or the draw, the variants
            // are still checked (the file does not compile anyway).
            let aggregate = aggregate.unwrap_or(Aggregate::Mean);
            st.variants = Some(VariantsSt { aggregate, draw, decls: v.variants.clone(), span: v.span });
        }
    }

    /// The variants' worlds: each variant's changes applied to the stage's
    /// world. Errors are reported where the variants are declared (`decl`
    /// the stage's span): an inherited variant's are not reported again.
    pub(super) fn variant_worlds(
        &mut self,
        st: &StageSt,
        sname: &str,
        decl: &ast::StageDecl,
    ) -> Option<Variants> {
        let v = st.variants.as_ref()?;
        let here = decl.span.start <= v.span.start && v.span.end <= decl.span.end;
        match &st.run {
            StageRun::Train { .. } if here => self.value_error(
                v.span,
                format!("training stage `{sname}` declares variants"),
                "a training stage lives one life",
                Some("declare the variants in a stage that evolves (or tests) the modules".into()),
            ),
            StageRun::Test { lives, .. } if (*lives as usize) < v.decls.len() => {
                let at = decl.items.iter().find_map(|i| match i {
                    ast::StageItem::Test { span, .. } => Some(*span),
                    _ => None,
                });
                self.value_error(
                    at.unwrap_or(v.span),
                    format!(
                        "test stage `{sname}` runs {lives} {}, fewer than its {} variants",
                        if *lives == 1 { "life" } else { "lives" },
                        v.decls.len()
                    ),
                    "not every variant is tested",
                    Some(format!("life k runs in variant k mod {}: test at least that many lives (`test best for {} lives of ...`)", v.decls.len(), v.decls.len())),
                );
            }
            _ => {}
        }
        // Errors of the variants themselves are reported where declared.
        let saved = self.errors.len();
        let mut list = Vec::with_capacity(v.decls.len());
        for d in &v.decls {
            for item in &d.world.items {
                if matches!(item, ast::WorldItem::Arena { .. } | ast::WorldItem::Body { .. }) {
                    self.value_error(
                        item.span(),
                        format!("variant `{}` of stage `{sname}` changes the arena or the body", d.name.text),
                        "not an item of the world",
                        Some("a variant changes the world's items (walls, cylinders, lamps, zones, objects, the start, the charger); the arena and the body are the stage's".into()),
                    );
                }
            }
            let mut ws = st.world.clone();
            let label = format!("{sname}`, variant `{}", d.name.text);
            self.world(&mut ws, &d.world, &label);
            let what = format!("variant `{}` of stage `{sname}`", d.name.text);
            self.role_robots(&mut ws, &st.roles, &st.role_heads, d.span, what);
            self.check_charger(&ws);
            self.check_items(&ws, d.span);
            self.check_crowded(&ws, d.span);
            self.check_team(&ws, d.span);
            let mut world = ws.world;
            world.arena = st.world.world.arena;
            world.body = st.world.world.body.clone();
            list.push(Variant { name: d.name.text.clone(), world });
        }
        if !here {
            self.errors.truncate(saved);
        }
        (!list.is_empty()).then_some(Variants { aggregate: v.aggregate, draw: v.draw, list })
    }
}
