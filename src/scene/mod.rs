//! Scene loading: XML parsing ([`xml`]), typed properties ([`desc`]), errors ([`error`]).

pub mod build;
pub mod desc;
pub mod error;
pub mod limits;
pub mod resolver;
pub mod world;
pub mod xml;

pub use error::{Error, Result, SrcPos};
