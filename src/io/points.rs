//! Reader for plain point files: one `x y z` per line.
