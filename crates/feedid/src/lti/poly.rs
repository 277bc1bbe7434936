//! Real polynomials in descending powers: roots and construction from roots.
