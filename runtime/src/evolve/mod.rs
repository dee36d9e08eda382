//! The incremental GA over stages (placeholder until the evolution issue lands).
