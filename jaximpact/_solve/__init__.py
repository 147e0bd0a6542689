"""How one contact and one drop are integrated: the impact (closed form, universal curves or
diffrax with events), the phases it is cut into, free flight, bounce sequences, the paper's
Euler baseline. Imports `_laws` and `_curves`."""
