//! Errors of model construction and of algorithms whose inputs can be physically invalid.

/// Everything that can go wrong in the core; each message names the offending item.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum Error {
    #[error("invalid model: {0}")]
    InvalidModel(String),
    #[error("invalid input: {0}")]
    InvalidInput(String),
    #[error("singular mass matrix: {0}")]
    SingularMassMatrix(String),
}

pub type Result<T> = std::result::Result<T, Error>;
