//! The size field (paper AG1).
