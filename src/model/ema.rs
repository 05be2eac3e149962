//! Exponential moving average of a module's weights: ema ← d·ema + (1−d)·current,
//! kept on a plain (non-autodiff) device. Parameters are matched by visiting order,
//! which is the same for two modules of the same type and shape.

use burn::module::{ModuleMapper, ModuleVisitor, Param};
use burn::prelude::*;

struct Collect(Vec<Tensor<1>>);

impl ModuleVisitor for Collect {
    fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
        let t = param.val().without_autodiff();
        let n = t.shape().num_elements();
        self.0.push(t.reshape([n]));
    }
}

struct Blend {
    current: std::vec::IntoIter<Tensor<1>>,
    decay: f32,
}

impl ModuleMapper for Blend {
    fn map_float<const D: usize>(&mut self, param: Param<Tensor<D>>) -> Param<Tensor<D>> {
        let cur = self
            .current
            .next()
            .expect("EMA and model have the same parameters");
        let decay = self.decay;
        param.map(|ema| {
            let dims = ema.dims();
            ema * decay + cur.reshape(dims) * (1.0 - decay)
        })
    }
}

/// Moves `ema` towards `current` by `1 − decay`.
pub fn ema_update<M: Module>(ema: M, current: &M, decay: f32) -> M {
    let mut collect = Collect(Vec::new());
    current.visit(&mut collect);
    ema.map(&mut Blend {
        current: collect.0.into_iter(),
        decay,
    })
}
