"""Figure and table makers: each turns the parameter file into one figure's SVG, its plotted data (CSV)
and the key numbers the paper quotes (JSON)."""
