//! The decoder of an [`crate::nn::Autoencoder`] as one [`CoefficientMap`], whichever its
//! [`DecoderForm`]: the folded network ([`DecoderMap`]) or the same scaled by `z₁` ([`ScaledMap`]).

use super::{DecoderForm, DecoderMap, ScaledMap};
use crate::map::CoefficientMap;

/// [`DecoderMap`] for [`DecoderForm::Plain`], [`ScaledMap`] of it for [`DecoderForm::Scaled`].
#[derive(Debug, Clone, PartialEq)]
pub enum AeDecoderMap {
    Plain(DecoderMap),
    Scaled(ScaledMap<DecoderMap>),
}

impl AeDecoderMap {
    /// The map of `form` around the folded network `map`.
    pub fn new(map: DecoderMap, form: DecoderForm) -> Self {
        match form {
            DecoderForm::Plain => AeDecoderMap::Plain(map),
            DecoderForm::Scaled => AeDecoderMap::Scaled(ScaledMap::new(map)),
        }
    }

    fn map(&self) -> &dyn CoefficientMap {
        match self {
            AeDecoderMap::Plain(m) => m,
            AeDecoderMap::Scaled(m) => m,
        }
    }
}

impl CoefficientMap for AeDecoderMap {
    fn n_in(&self) -> usize {
        self.map().n_in()
    }
    fn n_out(&self) -> usize {
        self.map().n_out()
    }
    fn scratch_len(&self) -> usize {
        self.map().scratch_len()
    }
    fn eval(&self, z: &[f64], c: &mut [f64], c_z: &mut [f64], scratch: &mut [f64]) {
        self.map().eval(z, c, c_z, scratch)
    }
    fn eval_value(&self, z: &[f64], c: &mut [f64], scratch: &mut [f64]) {
        self.map().eval_value(z, c, scratch)
    }
    fn eval_rate(&self, z: &[f64], zd: &[f64], c_z_dot: &mut [f64], scratch: &mut [f64]) {
        self.map().eval_rate(z, zd, c_z_dot, scratch)
    }
    fn add_weighted_hessian(&self, z: &[f64], g: &[f64], out: &mut [f64], scratch: &mut [f64]) {
        self.map().add_weighted_hessian(z, g, out, scratch)
    }
    fn eval_motion(
        &self,
        z: &[f64],
        zd: &[f64],
        zdd: Option<&[f64]>,
        c: &mut [f64],
        c_dot: &mut [f64],
        c_acc: &mut [f64],
        scratch: &mut [f64],
    ) {
        self.map().eval_motion(z, zd, zdd, c, c_dot, c_acc, scratch)
    }
    fn vjp(&self, g: &[f64], out: &mut [f64], scratch: &mut [f64]) {
        self.map().vjp(g, out, scratch)
    }
}
