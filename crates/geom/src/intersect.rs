//! Exact intersection tests between segments and triangles.
