//! Decoded feed-forward sigmoid networks, their forward pass and one CRBP
//! (generalised delta rule) training step.

use crate::catalog::CHANNELS;
use crate::program::CrbpError;

/// The logistic function.
#[inline]
pub fn sigmoid(x: f32) -> f32 {
    1.0 / (1.0 + (-x).exp())
}

/// A decoded network (weights in the order of [`crate::program::Network`])
/// with the state of its last forward pass, so that a training step after the
/// action uses the outputs that produced it. The inputs are read from the
/// percept given to [`Net::forward`], which [`Net::train`] must be given again.
#[derive(Clone, Debug)]
pub struct Net {
    /// Percept channels feeding the inputs, in order.
    chans: Vec<u16>,
    /// First channel when `chans` is a run of consecutive channels (the
    /// inputs are then read straight from the percept).
    run: Option<usize>,
    hidden: usize,
    outputs: usize,
    /// Weights, `Network::params` order: per unit, bias first.
    pub(crate) w: Vec<f32>,
    /// Scratch: gathered inputs when the channels are not consecutive.
    x: Vec<f32>,
    /// Hidden activations of the last forward pass.
    h: Vec<f32>,
    /// The context of the last forward pass: the hidden activations of the
    /// one before (0 at first; empty unless recurrent).
    ctx: Vec<f32>,
    /// Outputs of the last forward pass.
    y: Vec<f32>,
    /// Net inputs of the output units in the last forward pass (what the
    /// sigmoid was applied to: ordered like the outputs, never saturated).
    z: Vec<f32>,
    /// Scratch: output deltas.
    dy: Vec<f32>,
}

/// The network's inputs on `percept`: a slice of it for a run of consecutive
/// channels, else gathered into `scratch`.
#[inline]
fn inputs<'a>(
    chans: &[u16],
    run: Option<usize>,
    scratch: &'a mut [f32],
    percept: &'a [f32; CHANNELS],
) -> &'a [f32] {
    match run {
        Some(s) => &percept[s..s + chans.len()],
        None => {
            for (x, &c) in scratch.iter_mut().zip(chans) {
                *x = percept[c as usize];
            }
            scratch
        }
    }
}

impl Net {
    /// A network over the given channels; `w` must hold
    /// `Network::param_count(chans.len(), hidden, outputs)` weights.
    pub fn new(chans: Vec<u16>, hidden: usize, outputs: usize, w: Vec<f32>) -> Net {
        Net::with_context(chans, hidden, outputs, false, w)
    }

    /// A network, recurrent (Elman) or not; `w` must hold
    /// `Network::param_count_of(chans.len(), hidden, outputs, recurrent)` weights.
    pub fn with_context(chans: Vec<u16>, hidden: usize, outputs: usize, recurrent: bool, w: Vec<f32>) -> Net {
        let n = chans.len();
        let recurrent = recurrent && hidden > 0;
        debug_assert_eq!(w.len(), crate::program::Network::param_count_of(n, hidden, outputs, recurrent));
        let run = match chans.first() {
            Some(&c0) if chans.iter().enumerate().all(|(i, &c)| c as usize == c0 as usize + i) => {
                Some(c0 as usize)
            }
            Some(_) => None,
            None => Some(0),
        };
        Net {
            chans,
            run,
            hidden,
            outputs,
            w,
            x: vec![0.0; n],
            h: vec![0.0; hidden],
            ctx: vec![0.0; if recurrent { hidden } else { 0 }],
            y: vec![0.0; outputs],
            z: vec![0.0; outputs],
            dy: vec![0.0; outputs],
        }
    }

    pub fn outputs(&self) -> &[f32] {
        &self.y
    }

    /// Net inputs of the output units in the last forward pass.
    pub fn net_inputs(&self) -> &[f32] {
        &self.z
    }

    /// One sigmoid unit straight on the inputs (no hidden layer, one output).
    pub(crate) fn is_single_unit(&self) -> bool {
        self.hidden == 0 && self.outputs == 1 && self.ctx.is_empty()
    }

    /// The percept channels feeding the inputs, in order.
    pub(crate) fn channels(&self) -> &[u16] {
        &self.chans
    }

    /// Records a forward pass of a single unit computed elsewhere (by a
    /// [`super::block::Block`]) from its net input `z`, as [`Net::forward`]
    /// would have: the output is `sigmoid(z)`, returned.
    #[inline]
    pub(crate) fn record_single(&mut self, z: f32) -> f32 {
        let y = sigmoid(z);
        self.z[0] = z;
        self.y[0] = y;
        y
    }

    /// Forgets the last forward pass: a recurrent network's next context is
    /// zero again, as in a fresh network (the weights stay).
    pub fn forget(&mut self) {
        self.h.fill(0.0);
        self.ctx.fill(0.0);
    }

    /// Forward pass on a percept; `extra` is added to every output neuron's net
    /// input (the link term of an activation network).
    #[inline]
    pub fn forward(&mut self, percept: &[f32; CHANNELS], extra: f32) -> &[f32] {
        let Net { chans, run, hidden, w, x, h, ctx, y, z, .. } = self;
        let x = inputs(chans, *run, x, percept);
        let n = x.len();
        if !ctx.is_empty() {
            // Elman: the context is the previous pass's hidden layer.
            ctx.copy_from_slice(h);
            let c = ctx.len();
            let u = n + 1 + c;
            for (j, h) in h.iter_mut().enumerate() {
                let row = &w[j * u..(j + 1) * u];
                *h = sigmoid(row[0] + dot(&row[1..n + 1], x) + dot(&row[n + 1..], ctx));
            }
            let base = *hidden * u;
            let m = *hidden + 1;
            for (o, (y, z)) in y.iter_mut().zip(z.iter_mut()).enumerate() {
                let row = &w[base + o * m..base + (o + 1) * m];
                *z = row[0] + dot(&row[1..], h) + extra;
                *y = sigmoid(*z);
            }
        } else if *hidden == 0 {
            for (o, (y, z)) in y.iter_mut().zip(z.iter_mut()).enumerate() {
                let row = &w[o * (n + 1)..(o + 1) * (n + 1)];
                *z = row[0] + dot(&row[1..], x) + extra;
                *y = sigmoid(*z);
            }
        } else {
            for (j, h) in h.iter_mut().enumerate() {
                let row = &w[j * (n + 1)..(j + 1) * (n + 1)];
                *h = sigmoid(row[0] + dot(&row[1..], x));
            }
            let base = *hidden * (n + 1);
            let m = *hidden + 1;
            for (o, (y, z)) in y.iter_mut().zip(z.iter_mut()).enumerate() {
                let row = &w[base + o * m..base + (o + 1) * m];
                *z = row[0] + dot(&row[1..], h) + extra;
                *y = sigmoid(*z);
            }
        }
        &self.y
    }

    /// One step of the generalised delta rule on the last forward pass (whose
    /// percept must be given again) toward the targets `target(o)` (sigmoid
    /// units, biases as weights on a constant 1): the output delta is
    /// `t - y` ([`CrbpError::Difference`]) or `(t - y) y (1 - y)`
    /// ([`CrbpError::Squared`]), `dw = rate * delta * input`, and hidden
    /// units back-propagate it through the sigmoid's derivative.
    pub fn train(
        &mut self,
        percept: &[f32; CHANNELS],
        target: impl Fn(usize) -> f32,
        rate: f32,
        error: CrbpError,
    ) {
        let Net { chans, run, hidden, outputs, w, x, h, ctx, y, dy, .. } = self;
        let x = inputs(chans, *run, x, percept);
        let n = x.len();
        for (o, (d, &y)) in dy.iter_mut().zip(y.iter()).enumerate() {
            *d = match error {
                CrbpError::Difference => target(o) - y,
                CrbpError::Squared => (target(o) - y) * y * (1.0 - y),
            };
        }
        if *hidden == 0 {
            for o in 0..*outputs {
                let g = rate * dy[o];
                let row = &mut w[o * (n + 1)..(o + 1) * (n + 1)];
                row[0] += g;
                for (w, &x) in row[1..].iter_mut().zip(x) {
                    *w += g * x;
                }
            }
            return;
        }
        // A hidden unit's row: bias, inputs, then the context (recurrent);
        // the context is an input like the others (one step back, no
        // propagation through time).
        let u = n + 1 + ctx.len();
        let base = *hidden * u;
        let m = *hidden + 1;
        // Hidden deltas from the weights before this update.
        for j in 0..*hidden {
            let back: f32 = (0..*outputs).map(|o| w[base + o * m + 1 + j] * dy[o]).sum();
            let hj = h[j];
            let g = rate * back * hj * (1.0 - hj);
            let row = &mut w[j * u..(j + 1) * u];
            row[0] += g;
            for (w, &x) in row[1..].iter_mut().zip(x.iter().chain(ctx.iter())) {
                *w += g * x;
            }
        }
        for o in 0..*outputs {
            let g = rate * dy[o];
            let row = &mut w[base + o * m..base + (o + 1) * m];
            row[0] += g;
            for (w, &h) in row[1..].iter_mut().zip(h.iter()) {
                *w += g * h;
            }
        }
    }
}

#[inline]
fn dot(a: &[f32], b: &[f32]) -> f32 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forward_matches_hand_computation() {
        // 2 inputs, no hidden, 1 output: bias 0.5, w = [1, -2].
        let mut net = Net::new(vec![0, 1], 0, 1, vec![0.5, 1.0, -2.0]);
        let mut p = [0.0; CHANNELS];
        p[0] = 0.3;
        p[1] = 0.4;
        let y = net.forward(&p, 0.25)[0];
        assert!((y - sigmoid(0.5 + 0.3 - 0.8 + 0.25)).abs() < 1e-6);
    }

    #[test]
    fn training_moves_outputs_toward_targets_with_a_hidden_layer() {
        let w: Vec<f32> =
            (0..Network::param_count(3, 2, 2)).map(|i| ((i * 7 % 5) as f32 - 2.0) * 0.3).collect();
        // Channels 2, 0, 1: not a run, so the inputs are gathered.
        let mut net = Net::new(vec![2, 0, 1], 2, 2, w);
        let mut p = [0.0; CHANNELS];
        p[2] = 1.0;
        p[1] = 0.5;
        let before = net.forward(&p, 0.0).to_vec();
        for _ in 0..50 {
            net.forward(&p, 0.0);
            net.train(&p, |o| if o == 0 { 1.0 } else { 0.0 }, 0.5, CrbpError::Squared);
        }
        let after = net.forward(&p, 0.0).to_vec();
        assert!(after[0] > before[0] + 0.05, "{before:?} -> {after:?}");
        assert!(after[1] < before[1] - 0.05, "{before:?} -> {after:?}");
    }

    #[test]
    fn recurrent_hidden_units_read_the_previous_pass() {
        // 1 input, 1 recurrent hidden unit, 1 output: h = s(0 + 1 x + 2 c),
        // y = s(0 + 1 h).
        let mut net = Net::with_context(vec![0], 1, 1, true, vec![0.0, 1.0, 2.0, 0.0, 1.0]);
        assert_eq!(Network::param_count_of(1, 1, 1, true), 5);
        let p = [0.0; CHANNELS];
        let y1 = net.forward(&p, 0.0)[0];
        let h1 = sigmoid(0.0);
        assert!((y1 - sigmoid(h1)).abs() < 1e-6);
        // Same input, but the context is now h1: the output changes.
        let y2 = net.forward(&p, 0.0)[0];
        let h2 = sigmoid(2.0 * h1);
        assert!((y2 - sigmoid(h2)).abs() < 1e-6, "{y2} vs {}", sigmoid(h2));
        assert!(y2 > y1);
        // A fresh network starts from a zero context again.
        let mut fresh = Net::with_context(vec![0], 1, 1, true, vec![0.0, 1.0, 2.0, 0.0, 1.0]);
        assert_eq!(fresh.forward(&p, 0.0)[0], y1);
    }

    use crate::program::Network;
}
