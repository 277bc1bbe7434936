//! Reading recordings from CSV/text and MATLAB v5 files, and writing results.
