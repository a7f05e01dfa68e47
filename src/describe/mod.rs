//! describe (in progress)
