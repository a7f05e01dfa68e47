//! recognize (in progress)
