//! The performance indicator: rolling mean of a module's non-zero
//! reinforcement signals.

/// Rolling mean over the last `window` values pushed (fewer at the start; 0
/// when nothing was pushed yet). Fixed storage, no allocation after `new`.
#[derive(Clone, Debug)]
pub struct Rolling {
    buf: Vec<f32>,
    next: usize,
    len: usize,
    sum: f32,
}

impl Rolling {
    pub fn new(window: usize) -> Rolling {
        Rolling { buf: vec![0.0; window.max(1)], next: 0, len: 0, sum: 0.0 }
    }

    pub fn clear(&mut self) {
        self.next = 0;
        self.len = 0;
        self.sum = 0.0;
    }

    pub fn push(&mut self, v: f32) {
        if self.len == self.buf.len() {
            self.sum -= self.buf[self.next];
        } else {
            self.len += 1;
        }
        self.buf[self.next] = v;
        self.sum += v;
        self.next = (self.next + 1) % self.buf.len();
        // Recompute now and then so float drift cannot accumulate.
        if self.next == 0 {
            self.sum = self.buf[..self.len].iter().sum();
        }
    }

    pub fn mean(&self) -> f32 {
        if self.len == 0 {
            0.0
        } else {
            self.sum / self.len as f32
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_over_the_last_window_values() {
        let mut r = Rolling::new(3);
        assert_eq!(r.mean(), 0.0);
        r.push(1.0);
        assert_eq!(r.mean(), 1.0);
        r.push(-1.0);
        assert_eq!(r.mean(), 0.0);
        r.push(1.0);
        r.push(1.0);
        assert!((r.mean() - 1.0 / 3.0).abs() < 1e-6, "(-1 + 1 + 1) / 3, got {}", r.mean());
        r.push(1.0);
        assert_eq!(r.mean(), 1.0);
    }
}
