"""Parameters from measurements: `calibrate` on target e and T, `fit_bounces` on impact times
or trajectories, model choice among laws. Imports `_solve`, `_curves` and `_laws`."""
