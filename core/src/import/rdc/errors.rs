//! Why a converted RenderDoc capture cannot be read: a chunk's damage (a member of the zip
//! missing or of the wrong size, a chunk without its parts) and a parameter's, located by its
//! path through the chunk.

use super::members::MemberError;

/// Why a chunk cannot be fed to the importer: a damaged file (a member missing or of the
/// wrong size, a parameter that is not what its type says, a chunk without its parts).
#[derive(Debug, thiserror::Error)]
pub enum ChunkError {
    #[error("a <buffer> without a byteLength")]
    NoByteLength,
    #[error("vkGetSwapchainImagesKHR without Swapchain, SwapchainImageIndex and SwapchainImage")]
    SwapchainParts,
    #[error("initial contents without an id")]
    NoId,
    #[error(transparent)]
    Member(#[from] MemberError),
    #[error(transparent)]
    Arg(#[from] Box<ArgError>),
}

impl From<ArgError> for ChunkError {
    fn from(e: ArgError) -> ChunkError {
        ChunkError::Arg(Box::new(e))
    }
}

/// A parameter that cannot be read: where (the parameter and the members and elements down
/// to the value, `CreateInfo: extent: width`) and why.
#[derive(Debug)]
pub struct ArgError {
    /// Innermost first: each level adds its name as the error passes up.
    path: Vec<String>,
    pub problem: ArgProblem,
}

impl std::fmt::Display for ArgError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for part in self.path.iter().rev() {
            write!(f, "{part}: ")?;
        }
        write!(f, "{}", self.problem)
    }
}

impl std::error::Error for ArgError {}

impl ArgError {
    pub(super) fn within(mut self, part: impl std::fmt::Display) -> ArgError {
        self.path.push(part.to_string());
        self
    }
}

impl From<ArgProblem> for ArgError {
    fn from(problem: ArgProblem) -> ArgError {
        ArgError {
            path: Vec::new(),
            problem,
        }
    }
}

impl From<ChunkError> for ArgError {
    fn from(e: ChunkError) -> ArgError {
        ArgProblem::Bytes(Box::new(e)).into()
    }
}

/// What is wrong with a parameter's value.
#[derive(Debug, thiserror::Error)]
pub enum ArgProblem {
    #[error("\"{0}\" is not an unsigned number")]
    NotUnsigned(String),
    #[error("\"{0}\" is not a number")]
    NotNumber(String),
    #[error(transparent)]
    Bytes(Box<ChunkError>),
}
