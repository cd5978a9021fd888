//! The backend-agnostic trace API.
