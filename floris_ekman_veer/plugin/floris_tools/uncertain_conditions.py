"""UncertainFlorisModel on per-condition atmospheres.

UncertainFlorisModel (FLORIS 4.7) rounds its conditions, stacks ``n_sample_points`` copies of
them with perturbed wind directions (``_expand_wind_directions``) and keeps the unique rows
(``_get_unique_inputs``) for the model it runs. A per-condition atmosphere list (one entry per
unexpanded condition) cannot follow that by itself, and two conditions that differ only by their
atmosphere would be merged. The wrapper of ``_set_uncertain`` therefore

* appends each row's atmosphere label as a column before the unique rows are taken, so rows of
  different atmospheres are never merged, and reads the labels of the unique rows back;
* checks, rather than assumes, the stacking: the expanded rows must be the rounded conditions
  repeated block by block (wind speed and turbulence intensity columns equal), else it raises;
* builds the expanded model without the atmosphere, then gives it the unique rows' atmospheres
  (docs/coupling.md#yaw-optimisation).

Results are those of one UncertainFlorisModel per distinct atmosphere
(tests/studies/yaw/test_optimization.py).
"""

from __future__ import annotations

import functools

import numpy as np

from floris_ekman_veer.plugin.inflow.atmosphere_block import (
    atmosphere_groups,
    atmosphere_of,
    replaced_atmosphere,
    set_atmosphere,
)


def per_condition_set_uncertain(original):
    """UncertainFlorisModel._set_uncertain on per-condition atmospheres (FLORIS's own otherwise)."""

    @functools.wraps(original)
    def wrapper(self) -> None:
        fmodel = self.fmodel_unexpanded
        spec = atmosphere_of(fmodel.core)
        if spec is None or spec.n_conditions is None:
            return original(self)
        groups = atmosphere_groups(fmodel)
        labels = np.empty(fmodel.core.flow_field.n_findex, dtype=int)
        for label, (_, index) in enumerate(groups):
            labels[index] = label
        unique_labels = []
        floris_unique = self._get_unique_inputs

        def unique_with_atmosphere(expanded):
            copies, remainder = divmod(expanded.shape[0], labels.size)
            rounded = np.tile(self.rounded_inputs[:, 1:3], (max(copies, 1), 1))
            if remainder or not np.array_equal(expanded[:, 1:3], rounded):
                raise RuntimeError(
                    "UncertainFlorisModel's expanded conditions are not copies of its rounded "
                    "conditions in order; per-condition atmospheres cannot be assigned to them "
                    "(unsupported FLORIS version?)"
                )
            tagged = np.column_stack([expanded, np.tile(labels, copies)])
            unique, mapping = floris_unique(tagged)
            unique_labels.append(unique[:, -1].astype(int))
            return unique[:, :-1], mapping

        self._get_unique_inputs = unique_with_atmosphere
        try:
            with replaced_atmosphere(fmodel.core, None):
                original(self)
        finally:
            del self._get_unique_inputs
        rows = unique_labels[-1]
        atmosphere = {
            name: value if isinstance(value, float) else [groups[k][0][name] for k in rows]
            for name, value in spec.inputs.items()
        }
        set_atmosphere(self.fmodel_expanded, atmosphere)

    return wrapper
