"""Result tables that print whole (docs/user_guide.md#annual-energy-with-wake-steering).

``print(result.table)`` in a plain terminal would let pandas cut the columns to the terminal's
width (the baseline and steered energies among them, behind "..."); a :class:`FullTable` prints
every row and column. It is a pandas DataFrame in every other respect.
"""

from __future__ import annotations

import pandas as pd


class FullTable(pd.DataFrame):
    """A DataFrame whose ``str``/``repr`` is ``to_string()``: every row and column, at any
    terminal width (selections of it are FullTables too)."""

    @property
    def _constructor(self):
        return FullTable

    def __repr__(self) -> str:
        return self.to_string()
