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
        let mut placed = Vec::new();
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
            self.role_robots(&mut ws, &st.roles, &st.role_heads, d.span, what, None);
            self.check_charger(&ws);
            self.check_items(&ws, d.span);
            self.check_crowded(&ws, d.span);
            self.check_team(&ws, d.span);
            if !ws.world.items.places.is_empty() {
                placed.push((ws.clone(), d.span));
            }
            let mut world = ws.world;
            world.arena = st.world.world.arena;
            world.body = st.world.world.body.clone();
            list.push(Variant { name: d.name.text.clone(), world });
        }
        if !here {
            self.errors.truncate(saved);
            self.variants_undo_changes(v, st, sname, decl);
        }
        // A variant's placements after the life's end: where the variant is
        // declared, and again in a stage that sets a shorter life.
        let (life, life_span) = super::life(&st.run, decl);
        for (ws, vspan) in &placed {
            let in_variant = |sp: Span| vspan.start <= sp.start && sp.end <= vspan.end;
            self.check_place_life(ws, sname, life, life_span, &|sp| {
                in_variant(sp) && (here || life_span.is_some())
            });
        }
        (!list.is_empty()).then_some(Variants { aggregate: v.aggregate, draw: v.draw, list })
    }

    /// The warning `S0032` for each item of `decl`'s own world blocks that
    /// a variant it inherits (`v`) restates: the variant is applied to the
    /// stage's world after the stage's changes, so in that variant the
    /// stage's item is the variant's. With roles, the robots are the
    /// roles' in every world (`S0027` says so): no change of them is lost.
    fn variants_undo_changes(&mut self, v: &VariantsSt, st: &StageSt, sname: &str, decl: &ast::StageDecl) {
        let own = decl.items.iter().filter_map(|i| match i {
            ast::StageItem::World(w) => Some(&w.items),
            _ => None,
        });
        let own: Vec<&ast::WorldItem> = own.flatten().collect();
        let from = self.file.stages.iter().find(|s| s.span.start <= v.span.start && v.span.end <= s.span.end);
        let from = from.map_or(String::new(), |s| s.name.text.clone());
        for d in &v.decls {
            for item in &d.world.items {
                let Some(mine) = own.iter().find(|o| restates(o, item)) else { continue };
                if !st.roles.is_empty() && item.key().0 == "robots" {
                    continue;
                }
                let item = match item.key() {
                    (kind, Some(name)) => format!("{kind} `{name}`"),
                    (kind, None) => format!("the {kind}"),
                };
                self.errors.push(Error::VariantUndoesChange {
                    span: mine.span().into(),
                    variant_span: d.world.items.iter().find(|i| restates(mine, i)).map_or(d.span, |i| i.span()).into(),
                    stage: sname.to_string(),
                    variant: d.name.text.clone(),
                    from: from.clone(),
                    item,
                    help: "the variants a stage inherits are applied to its world after its own changes: declare the stage's own `variants { ... }`, which replace them, with the change in each variant, or make the change in the variants".into(),
                });
            }
        }
    }
}

/// Whether world item `b` (of a variant) restates what `a` (of a stage)
/// sets: the same item of a list by name, the same setting, or, for
/// objects, a part of them both write.
fn restates(a: &ast::WorldItem, b: &ast::WorldItem) -> bool {
    use ast::WorldItem as W;
    if let (
        W::Objects { count: c1, diameter: d1, virtual_: v1, .. },
        W::Objects { count: c2, diameter: d2, virtual_: v2, .. },
    ) = (a, b)
    {
        return (c1.is_some() && c2.is_some())
            || (d1.is_some() && d2.is_some())
            || (v1.is_some() && v2.is_some());
    }
    match (a.key(), b.key()) {
        ((k1, Some(n1)), (k2, Some(n2))) => k1 == k2 && n1 == n2,
        ((k1, None), (k2, None)) => k1 == k2,
        _ => false,
    }
}
