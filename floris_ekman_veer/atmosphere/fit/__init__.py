"""The profile fit: the atmosphere from measured wind profiles (docs/measurements.md). The driver
(fit) and its stages: the options' and data's checks (fit_inputs), the starting points
(multistart), the Levenberg-Marquardt iteration (least_squares), the model at the data heights
(fit_model), the noise model and residuals (fit_residuals), the result (fit_result) and why a
record fits no atmosphere (misfit).

May import: the base and the physics (the atmosphere's other modules, through the solver's
interface); never FLORIS, the plugin or the studies (docs/architecture.md)."""
