"""floris-ekman-veer: the veer-corrected curled-wake model of Narasimhan, Gayme & Meneveau
(JRSE 2025) and its coupled Ekman-surface-layer inflow, for FLORIS v4."""

from floris_ekman_veer.atmosphere.ekman import EkmanABL

__all__ = ["EkmanABL"]
__version__ = "0.1.0"
