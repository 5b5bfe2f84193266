//! The measured error tables behind the presets' budgets, one module per technique crate
//! (the reference's and `auto`'s tables sit beside their presets).

pub mod afsm;
pub mod dcs;
pub mod ssm;
