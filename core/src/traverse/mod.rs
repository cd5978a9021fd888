//! Traversal state machines.
