//! Analytic test meshes whose exact answer is known in closed form: parametric surfaces with
//! their exact tangents ([`tangents`]) and a displaced torus with its exact normals ([`torus`]).
//! `bumpbake bench` measures the engines against them and the tests hold the engines to them;
//! bumpbake's own commands never need them (feature `analytic`, on by default).

pub mod tangents;
pub mod torus;
