//! Question to query translation (being written).
