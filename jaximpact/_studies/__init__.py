"""What-if studies over batches: restitution maps, sensitivity, uncertainty propagation,
bumper and drop design. Imports `_batch`, `_fit`, `_solve` and `_laws`."""
