//! Errors of model construction and of algorithms whose inputs can be physically invalid.

/// Everything that can go wrong in the core; each message names the offending item.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum Error {
    #[error("invalid model: {0}")]
    InvalidModel(String),
    /// A joint record given to [`crate::model::ModelBuilder`] is wrong: `joint` is its index in
    /// the order given, `name` its name, `message` what is wrong with it.
    #[error("invalid model: joint '{name}' (joint {joint}): {message}")]
    InvalidJoint {
        joint: usize,
        name: String,
        message: String,
    },
    #[error("invalid input: {0}")]
    InvalidInput(String),
    /// Forward dynamics or M^-1 is undefined: the pivot of `joint` (a body, a degree of freedom) is
    /// not a positive part of M. `overflow`: the numbers were too large for float64 (finite
    /// inputs, an inertia or a state beyond float64's range), not a physically singular M.
    #[error("singular mass matrix: {message}")]
    SingularMassMatrix {
        joint: usize,
        overflow: bool,
        message: String,
    },
}

pub type Result<T> = std::result::Result<T, Error>;
