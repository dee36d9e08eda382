//! Links between modules and the genome layout: which genes a stage
//! introduces, and in which order.

use std::collections::HashMap;

use shaping_runtime::program::*;

use super::*;
use crate::diag::{did_you_mean, Error};
use crate::syntax::ast;
use crate::syntax::Span;

impl Lower<'_> {
    pub(super) fn links(&mut self, st: &mut StageSt, decl: &ast::StageDecl, s: u16) {
        let (modules, links) = (&st.modules, &mut st.links);
        self.links_of(modules, links, &decl.name.text, &decl.items, s, None);
    }

    /// The links of `items` (a stage's, or a role's) between `modules`,
    /// into `links`. For a role, `role` is its name and the modules of the
    /// stage's other roles, with their role's name: a link to one of them
    /// is refused as such.
    pub(super) fn links_of(
        &mut self,
        modules: &[ModuleSt],
        links: &mut Vec<LinkSt>,
        stage: &str,
        items: &[ast::StageItem],
        s: u16,
        role: Option<(&str, &[(String, String)])>,
    ) {
        let (role, others) = role.unwrap_or(("", &[]));
        use ast::StageItem as I;
        let names: Vec<String> = modules.iter().map(|m| m.name.clone()).collect();
        let mut link_index: HashMap<(u16, u16), usize> =
            links.iter().enumerate().map(|(k, x)| ((x.from, x.to), k)).collect();
        for item in items {
            let I::Link(l) = item else { continue };
            let from = self.link_end(&names, role, others, &l.from);
            let to = self.link_end(&names, role, others, &l.to);
            let (Some(from), Some(to)) = (from, to) else { continue };
            let kind = match &l.kind {
                ast::LinkKind::Evolvable(r) => Ok(r.as_ref().and_then(|r| self.range(r))),
                ast::LinkKind::Fixed(w) => Err(*w as f32),
            };
            if let Some(old) = link_index.get(&(from, to)).map(|&k| &links[k]) {
                if old.stage == s {
                    self.errors.push(Error::Duplicate {
                        span: l.span.into(),
                        first: old.span.into(),
                        what: "link",
                        name: format!("{} -> {}", l.from.text, l.to.text),
                    });
                } else {
                    self.errors.push(Error::Frozen {
                        span: l.span.into(),
                        frozen: old.span.into(),
                        stage: stage.to_string(),
                        by: self.stage_names[old.stage as usize].clone(),
                        what: format!("the link `{} -> {}`", l.from.text, l.to.text),
                    });
                }
                continue;
            }
            link_index.insert((from, to), links.len());
            links.push(LinkSt { from, to, kind, param: None, stage: s, span: l.span });
        }
        let mut all_span: Option<Span> = None;
        for item in items {
            let I::LinksAll(kind, span) = item else { continue };
            if let Some(first) = all_span {
                self.errors.push(Error::Duplicate {
                    span: (*span).into(),
                    first: first.into(),
                    what: "link declaration",
                    name: "links all".into(),
                });
                continue;
            }
            all_span = Some(*span);
            let kind = match kind {
                ast::LinkKind::Evolvable(r) => Ok(r.as_ref().and_then(|r| self.range(r))),
                ast::LinkKind::Fixed(w) => Err(*w as f32),
            };
            let n = modules.len() as u16;
            for to in 0..n {
                for from in 0..n {
                    if from != to && !link_index.contains_key(&(from, to)) {
                        links.push(LinkSt { from, to, kind, param: None, stage: s, span: *span });
                    }
                }
            }
        }
    }

    /// The module a link names, as its index in `names` (the modules of the
    /// stage, or of the role `role`); a module of one of the `others` roles,
    /// or an unknown one, is reported.
    fn link_end(
        &mut self,
        names: &[String],
        role: &str,
        others: &[(String, String)],
        n: &ast::Name,
    ) -> Option<u16> {
        if let Some(i) = names.iter().position(|m| *m == n.text) {
            return Some(i as u16);
        }
        if let Some((_, other)) = others.iter().find(|(m, _)| *m == n.text) {
            self.errors.push(Error::LinkAcrossRoles {
                span: n.span.into(),
                module: n.text.clone(),
                role: role.to_string(),
                other: other.clone(),
                help: format!(
                    "each robot runs its role's modules only, so a link joins two modules of one role: link `{}` to a module of role `{role}`, or give role `{role}` a module of its own",
                    n.text
                ),
            });
            return None;
        }
        let help = match self.module_origin.get(&n.text) {
            Some(origin) => Some(format!(
                "`{}` is declared by stage `{origin}`, which does not come before this one",
                n.text
            )),
            None => did_you_mean(&n.text, names.iter().map(String::as_str)),
        };
        self.errors.push(Error::Unknown { span: n.span.into(), what: "module", name: n.text.clone(), help });
        None
    }

    /// Appends the genes this stage introduces, in the order of the paper's
    /// fig. 2: for each module in order, its new activation genes (in the
    /// parameter order of `Network`), then its new behavior genes, then its
    /// new incoming link genes (from modules in order).
    pub(super) fn allocate(&mut self, st: &mut StageSt, s: u16) {
        let genome = st.genome;
        let mut genes = std::mem::take(&mut st.genes);
        let mut bits = st.bits;
        let mut push = |genes: &mut Vec<Gene>,
                        spec: GeneSpec,
                        range: Option<(f32, f32)>,
                        module: u16,
                        role: GeneRole|
         -> Param {
            let (lo, hi) = range.unwrap_or((spec.lo, spec.hi));
            genes.push(Gene { offset: bits, bits: spec.bits, lo, hi, stage: s, module, role, frozen: false });
            bits += spec.bits as u32;
            Param::Gene(genes.len() as u32 - 1)
        };
        // The links this stage introduces, by receiving module, from modules in order.
        let mut incoming: Vec<Vec<usize>> = vec![Vec::new(); st.modules.len()];
        for (k, l) in st.links.iter().enumerate() {
            if l.stage == s {
                if let Some(v) = incoming.get_mut(l.to as usize) {
                    v.push(k);
                }
            }
        }
        for v in &mut incoming {
            v.sort_by_key(|&k| st.links[k].from);
        }
        for (mi, incoming) in incoming.iter().enumerate() {
            let m = &mut st.modules[mi];
            if m.stage == s {
                if let Source::Evolvable(range) = m.source.clone() {
                    let roles = network_roles(m.inputs.len(), m.hidden as usize, 1, m.recurrent);
                    m.act_params = roles
                        .into_iter()
                        .map(|role| {
                            let spec = if is_bias(role) { genome.biases } else { genome.weights };
                            push(&mut genes, spec, range, mi as u16, role)
                        })
                        .collect();
                }
            }
            if m.behavior_stage == s {
                if let (Some(range), Some(Behavior::Neural(nb))) = (m.behavior_genes, m.behavior.as_mut()) {
                    let roles = network_roles(
                        nb.inputs.len(),
                        nb.net.hidden as usize,
                        nb.net.outputs as usize,
                        nb.net.recurrent,
                    );
                    nb.net.params = roles
                        .into_iter()
                        .map(|role| {
                            let spec = if is_bias(role) { genome.biases } else { genome.weights };
                            push(&mut genes, spec, range, mi as u16, role)
                        })
                        .collect();
                }
            }
            for &k in incoming {
                let l = &mut st.links[k];
                l.param = Some(match l.kind {
                    Ok(range) => push(&mut genes, genome.links, range, l.to, GeneRole::Link { from: l.from }),
                    Err(w) => Param::Fixed(w),
                });
            }
        }
        st.genes = genes;
        st.bits = bits;
    }
}

pub(super) fn is_bias(role: GeneRole) -> bool {
    matches!(role, GeneRole::Bias | GeneRole::HiddenBias { .. })
}

/// The roles of a network's parameters, in `Network::params` order.
pub(crate) fn network_roles(inputs: usize, hidden: usize, outputs: usize, recurrent: bool) -> Vec<GeneRole> {
    let mut roles = Vec::with_capacity(Network::param_count_of(inputs, hidden, outputs, recurrent));
    if hidden == 0 {
        for _ in 0..outputs {
            roles.push(GeneRole::Bias);
            roles.extend((0..inputs).map(|i| GeneRole::Weight { input: i as u16, hidden: None }));
        }
    } else {
        for h in 0..hidden {
            roles.push(GeneRole::HiddenBias { hidden: h as u16 });
            roles.extend((0..inputs).map(|i| GeneRole::Weight { input: i as u16, hidden: Some(h as u16) }));
            if recurrent {
                roles.extend((0..hidden).map(|f| GeneRole::Context { from: f as u16, hidden: h as u16 }));
            }
        }
        for _ in 0..outputs {
            roles.push(GeneRole::Bias);
            roles.extend((0..hidden).map(|h| GeneRole::HiddenOut { hidden: h as u16 }));
        }
    }
    roles
}
