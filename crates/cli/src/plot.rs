//! Histograms drawn with plotters.
