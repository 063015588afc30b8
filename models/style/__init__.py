"""Style after the generator (numpy): the stylizer's per-style parameters and causal filter, style read from
joint positions, and the style judge."""
