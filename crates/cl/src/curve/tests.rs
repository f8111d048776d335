//! Analytic tests of arcs and NURBS curves.
