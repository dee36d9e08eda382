//! The activation networks of up to [`LANES`] modules evaluated together.
//!
//! Most architectures' activation networks are one sigmoid unit on a few
//! channels (no hidden layer, no context). One at a time, each is a chain of
//! about nine dependent additions (a float sum keeps its order) and a call;
//! side by side, module `m` in lane `m`, the chains run in parallel and the
//! compiler vectorises the lanes. Each lane computes exactly what
//! [`super::Net::forward`] computes for its module: the products
//! `w[i] * x[i]` summed in input order from `-0.0` (as `Iterator::sum`
//! does), then `bias + sum + link`. A lane with fewer inputs than the longest
//! is padded with products `-0.0 * 0.0 = -0.0`, and `s + (-0.0) == s` for
//! every `s`, so the padding changes no bit.

use super::Net;
use crate::catalog::CHANNELS;

/// Modules a block holds.
pub const LANES: usize = 8;

/// A percept with room for the padding channel (index [`PAD`], always 0);
/// a power of two so that a masked index needs no bounds check.
const SPAN: usize = 64;
const PAD: u8 = CHANNELS as u8;
const _: () = assert!(CHANNELS < SPAN);

/// Input `k` of every lane: its channel and its weight.
#[derive(Clone, Debug)]
struct Row {
    chan: [u8; LANES],
    w: [f32; LANES],
}

#[derive(Clone, Debug)]
pub(crate) struct Block {
    lanes: usize,
    bias: [f32; LANES],
    rows: Vec<Row>,
}

impl Block {
    /// A block for these activation networks, if every one is a single
    /// sigmoid unit without hidden layer and there are at most [`LANES`].
    pub(crate) fn new<'a>(nets: impl ExactSizeIterator<Item = &'a Net>) -> Option<Block> {
        let lanes = nets.len();
        if lanes > LANES {
            return None;
        }
        let mut b = Block { lanes, bias: [0.0; LANES], rows: Vec::new() };
        for (m, net) in nets.enumerate() {
            if !net.is_single_unit() || net.channels().iter().any(|&c| c as usize >= CHANNELS) {
                return None;
            }
            b.load(m, net);
        }
        Some(b)
    }

    /// (Re)loads lane `m` from its network's current weights (after a
    /// training step changed them).
    pub(crate) fn load(&mut self, m: usize, net: &Net) {
        let chans = net.channels();
        while self.rows.len() < chans.len() {
            self.rows.push(Row { chan: [PAD; LANES], w: [-0.0; LANES] });
        }
        self.bias[m] = net.w[0];
        for (k, row) in self.rows.iter_mut().enumerate() {
            match chans.get(k) {
                Some(&c) => {
                    row.chan[m] = c as u8;
                    row.w[m] = net.w[1 + k];
                }
                None => {
                    row.chan[m] = PAD;
                    row.w[m] = -0.0;
                }
            }
        }
    }

    /// Every lane's net input on `percept` with its link term `link[m]`.
    #[inline]
    pub(crate) fn net_inputs(&self, percept: &[f32; CHANNELS], link: &[f32; LANES]) -> [f32; LANES] {
        let mut p = [0.0f32; SPAN];
        p[..CHANNELS].copy_from_slice(percept);
        let mut s = [-0.0f32; LANES];
        for row in &self.rows {
            let mut x = [0.0f32; LANES];
            for (x, &c) in x.iter_mut().zip(&row.chan) {
                *x = p[c as usize & (SPAN - 1)];
            }
            for l in 0..LANES {
                s[l] += row.w[l] * x[l];
            }
        }
        let mut z = [0.0f32; LANES];
        for l in 0..LANES {
            z[l] = self.bias[l] + s[l] + link[l];
        }
        z
    }

    pub(crate) fn lanes(&self) -> usize {
        self.lanes
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn lanes_give_the_bits_of_one_network_at_a_time() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for _ in 0..300 {
            let lanes = rng.random_range(1..=LANES);
            // Runs and gathered channels, lengths 0 to 12, awkward weights
            // (zeros of both signs) so that padding and signs are exercised.
            let mut nets: Vec<Net> = (0..lanes)
                .map(|_| {
                    let n = rng.random_range(0..=12usize);
                    let chans: Vec<u16> = if rng.random::<bool>() {
                        let s = rng.random_range(0..=CHANNELS - n) as u16;
                        (s..s + n as u16).collect()
                    } else {
                        (0..n).map(|_| rng.random_range(0..CHANNELS as u16)).collect()
                    };
                    let w = (0..=n)
                        .map(|_| match rng.random_range(0..4) {
                            0 => 0.0,
                            1 => -0.0,
                            _ => rng.random_range(-4.0f32..4.0),
                        })
                        .collect();
                    Net::new(chans, 0, 1, w)
                })
                .collect();
            let block = Block::new(nets.iter()).expect("single units fit");
            let mut p = [0.0f32; CHANNELS];
            for v in &mut p {
                *v = match rng.random_range(0..3) {
                    0 => 0.0,
                    1 => -0.0,
                    _ => rng.random_range(-1.0f32..1.0),
                };
            }
            let mut link = [0.0f32; LANES];
            for l in &mut link[..lanes] {
                *l = if rng.random::<bool>() { -0.0 } else { rng.random_range(-2.0f32..2.0) };
            }
            let z = block.net_inputs(&p, &link);
            for (m, net) in nets.iter_mut().enumerate() {
                let y = net.forward(&p, link[m])[0];
                let want = net.net_inputs()[0];
                assert_eq!(z[m].to_bits(), want.to_bits(), "lane {m}: {} vs {want}", z[m]);
                assert_eq!(net.record_single(z[m]).to_bits(), y.to_bits());
            }
        }
    }

    #[test]
    fn networks_that_do_not_fit_are_left_to_one_at_a_time() {
        let single = Net::new(vec![0, 1], 0, 1, vec![0.0; 3]);
        let hidden = Net::new(vec![0, 1], 1, 1, vec![0.0; 5]);
        let two = Net::new(vec![0], 0, 2, vec![0.0; 4]);
        assert!(Block::new([&single, &single].into_iter()).is_some());
        assert!(Block::new([&single, &hidden].into_iter()).is_none());
        assert!(Block::new([&two].into_iter()).is_none());
        assert!(Block::new(std::iter::repeat_n(&single, LANES + 1)).is_none());
    }
}
