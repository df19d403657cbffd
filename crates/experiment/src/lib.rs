//! Experiment layer: configs, the board assembled from the stages, Coriolis and rotating sweeps, theory overlays
