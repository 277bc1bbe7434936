//! The network itself, in plain `f64`: a multilayer perceptron with two
//! `tanh` hidden layers and a linear bypass,
//!
//! ```text
//! h₁ = tanh(W₁ᵀz + b₁),   h₂ = tanh(W₂ᵀh₁ + b₂),   f(z) = w₃ᵀh₂ + b₃ + lᵀz,
//! ```
//!
//! with its forward pass and the gradient of a squared error written out
//! (backpropagation by hand), both into caller-owned scratch, so that the
//! per-window paths (prediction, online updates) allocate nothing. The
//! batch training runs the same network in candle (module `train`); a test
//! checks that both compute the same outputs and gradients.
//!
//! Parameters are one flat vector, matrices stored input-major (`W₁[i, j]`
//! at `i·h + j`, the layout of a candle `(in, out)` tensor):
//! `W₁ (F×h) | b₁ (h) | W₂ (h×h) | b₂ (h) | w₃ (h) | b₃ | l (F)`.

/// Sizes of a network: `f` inputs, `h` neurons in each hidden layer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Shape {
    /// Inputs.
    pub f: usize,
    /// Neurons per hidden layer.
    pub h: usize,
}

/// Offsets of each block in the flat parameter vector.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Layout {
    pub w1: usize,
    pub b1: usize,
    pub w2: usize,
    pub b2: usize,
    pub w3: usize,
    pub b3: usize,
    pub l: usize,
    pub len: usize,
}

impl Shape {
    /// Where each block starts in the flat parameters.
    pub fn layout(self) -> Layout {
        let (f, h) = (self.f, self.h);
        let w1 = 0;
        let b1 = w1 + f * h;
        let w2 = b1 + h;
        let b2 = w2 + h * h;
        let w3 = b2 + h;
        let b3 = w3 + h;
        let l = b3 + 1;
        Layout {
            w1,
            b1,
            w2,
            b2,
            w3,
            b3,
            l,
            len: l + f,
        }
    }

    /// Number of parameters.
    pub fn params(self) -> usize {
        self.layout().len
    }
}

/// Buffers for one forward and backward pass (the hidden activations).
#[derive(Debug, Clone, Default)]
pub(crate) struct Scratch {
    h1: Vec<f64>,
    h2: Vec<f64>,
    d2: Vec<f64>,
}

impl Scratch {
    /// Buffers for networks of `shape`.
    pub fn new(shape: Shape) -> Self {
        Self {
            h1: vec![0.0; shape.h],
            h2: vec![0.0; shape.h],
            d2: vec![0.0; shape.h],
        }
    }
}

/// The network's output `f(z)` for the (scaled) input `z`.
pub(crate) fn forward(shape: Shape, p: &[f64], z: &[f64], s: &mut Scratch) -> f64 {
    let (f, h) = (shape.f, shape.h);
    let o = shape.layout();
    debug_assert_eq!(z.len(), f);
    debug_assert_eq!(p.len(), o.len);
    let h1 = &mut s.h1[..h];
    h1.copy_from_slice(&p[o.b1..o.b1 + h]);
    for (i, &zi) in z.iter().enumerate() {
        let row = &p[o.w1 + i * h..o.w1 + (i + 1) * h];
        for (a, &w) in h1.iter_mut().zip(row) {
            *a += zi * w;
        }
    }
    for a in h1.iter_mut() {
        *a = a.tanh();
    }
    let h2 = &mut s.h2[..h];
    h2.copy_from_slice(&p[o.b2..o.b2 + h]);
    for (i, &hi) in h1.iter().enumerate() {
        let row = &p[o.w2 + i * h..o.w2 + (i + 1) * h];
        for (a, &w) in h2.iter_mut().zip(row) {
            *a += hi * w;
        }
    }
    let mut out = p[o.b3];
    for (a, &w) in h2.iter_mut().zip(&p[o.w3..o.w3 + h]) {
        *a = a.tanh();
        out += *a * w;
    }
    for (&zi, &w) in z.iter().zip(&p[o.l..o.l + f]) {
        out += zi * w;
    }
    out
}

/// Add `g · ∂f(z)/∂p` to `grad`, where `g` is the derivative of the loss
/// with respect to the output; returns `f(z)`. Call with `g` from the
/// output of [`forward`] on the same `z`, or use [`add_squared_error_gradient`].
fn backward(shape: Shape, p: &[f64], z: &[f64], g: f64, s: &mut Scratch, grad: &mut [f64]) {
    let (f, h) = (shape.f, shape.h);
    let o = shape.layout();
    // output layer and bypass
    for j in 0..h {
        grad[o.w3 + j] += g * s.h2[j];
        s.d2[j] = g * p[o.w3 + j] * (1.0 - s.h2[j] * s.h2[j]);
    }
    grad[o.b3] += g;
    for i in 0..f {
        grad[o.l + i] += g * z[i];
    }
    // second hidden layer
    for a in 0..h {
        let mut back = 0.0;
        for j in 0..h {
            grad[o.w2 + a * h + j] += s.d2[j] * s.h1[a];
            back += p[o.w2 + a * h + j] * s.d2[j];
        }
        // δ₁[a], kept in h1's slot once its activation is used
        s.h1[a] = back * (1.0 - s.h1[a] * s.h1[a]);
    }
    for j in 0..h {
        grad[o.b2 + j] += s.d2[j];
    }
    // first hidden layer
    for i in 0..f {
        for a in 0..h {
            grad[o.w1 + i * h + a] += s.h1[a] * z[i];
        }
    }
    for a in 0..h {
        grad[o.b1 + a] += s.h1[a];
    }
}

/// Add the gradient of `weight · (f(z) − t)²` to `grad`; returns the error `f(z) − t`.
pub(crate) fn add_squared_error_gradient(
    shape: Shape,
    p: &[f64],
    z: &[f64],
    t: f64,
    weight: f64,
    s: &mut Scratch,
    grad: &mut [f64],
) -> f64 {
    let e = forward(shape, p, z, s) - t;
    backward(shape, p, z, 2.0 * weight * e, s, grad);
    e
}

/// Adam's moment estimates for the online updates (Kingma & Ba, 2015).
#[derive(Debug, Clone, Default)]
pub(crate) struct Adam {
    m: Vec<f64>,
    v: Vec<f64>,
    t: i32,
}

/// Adam's decay rates and denominator guard (the published defaults).
const BETA1: f64 = 0.9;
const BETA2: f64 = 0.999;
const EPSILON: f64 = 1e-8;

impl Adam {
    /// Moments of `n` parameters, zero.
    pub fn new(n: usize) -> Self {
        Self {
            m: vec![0.0; n],
            v: vec![0.0; n],
            t: 0,
        }
    }

    /// Forget the moments (after a batch training replaced the parameters).
    pub fn clear(&mut self) {
        self.m.fill(0.0);
        self.v.fill(0.0);
        self.t = 0;
    }

    /// One step of size `lr` on `p` along `grad`.
    pub fn step(&mut self, p: &mut [f64], grad: &[f64], lr: f64) {
        self.t = self.t.saturating_add(1);
        let c1 = 1.0 - BETA1.powi(self.t);
        let c2 = 1.0 - BETA2.powi(self.t);
        for (((w, &g), m), v) in p.iter_mut().zip(grad).zip(&mut self.m).zip(&mut self.v) {
            *m = BETA1 * *m + (1.0 - BETA1) * g;
            *v = BETA2 * *v + (1.0 - BETA2) * g * g;
            *w -= lr * (*m / c1) / ((*v / c2).sqrt() + EPSILON);
        }
    }
}

/// Adam's constants, for the batch training in candle.
pub(crate) const ADAM: (f64, f64, f64) = (BETA1, BETA2, EPSILON);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forward_matches_a_hand_computed_pass() {
        // f = 2, h = 2; every weight chosen by hand
        let shape = Shape { f: 2, h: 2 };
        #[rustfmt::skip]
        let p = [
            0.5, -0.25, // W1 row of input 0 (to hidden 0, 1)
            1.0, 0.75,  // W1 row of input 1
            0.1, -0.2,  // b1
            0.3, -0.6,  // W2 row of hidden 0
            0.9, 0.4,   // W2 row of hidden 1
            0.05, 0.0,  // b2
            1.5, -2.0,  // w3
            0.25,       // b3
            0.7, -0.1,  // l
        ];
        assert_eq!(p.len(), shape.params());
        let z = [0.4, -1.2];
        let a1 = (0.1_f64 + 0.4 * 0.5 - 1.2 * 1.0).tanh();
        let a2 = (-0.2_f64 + 0.4 * -0.25 - 1.2 * 0.75).tanh();
        let c1 = (0.05 + a1 * 0.3 + a2 * 0.9_f64).tanh();
        let c2 = (0.0 + a1 * -0.6 + a2 * 0.4_f64).tanh();
        let want = 0.25 + 1.5 * c1 - 2.0 * c2 + 0.7 * 0.4 - 0.1 * -1.2;
        let got = forward(shape, &p, &z, &mut Scratch::new(shape));
        assert!((got - want).abs() < 1e-15, "{got} vs {want}");
        // the same numbers written out: a1 = tanh(−0.9), a2 = tanh(−1.2), …
        assert!((a1 - (-0.9_f64).tanh()).abs() < 1e-15);
        assert!((a2 - (-1.2_f64).tanh()).abs() < 1e-15);
    }

    #[test]
    fn gradient_matches_central_differences() {
        let shape = Shape { f: 3, h: 4 };
        let n = shape.params();
        let p: Vec<f64> = (0..n)
            .map(|i| ((i * 7919) % 13) as f64 / 13.0 - 0.45)
            .collect();
        let z = [0.3, -0.8, 1.1];
        let t = 0.2;
        let mut s = Scratch::new(shape);
        let mut grad = vec![0.0; n];
        add_squared_error_gradient(shape, &p, &z, t, 1.0, &mut s, &mut grad);
        for k in 0..n {
            let h = 1e-6;
            let mut q = p.clone();
            q[k] += h;
            let up = (forward(shape, &q, &z, &mut s) - t).powi(2);
            q[k] -= 2.0 * h;
            let down = (forward(shape, &q, &z, &mut s) - t).powi(2);
            let fd = (up - down) / (2.0 * h);
            assert!(
                (grad[k] - fd).abs() < 1e-8,
                "parameter {k}: {} vs {fd}",
                grad[k]
            );
        }
    }

    #[test]
    fn adam_steps_down_a_quadratic() {
        let mut p = [3.0, -2.0];
        let mut adam = Adam::new(2);
        for _ in 0..2000 {
            let g = [2.0 * p[0], 2.0 * p[1]];
            adam.step(&mut p, &g, 0.01);
        }
        assert!(p[0].abs() < 1e-2 && p[1].abs() < 1e-2, "{p:?}");
    }
}
