"""The site fit: a site's measured wind profiles (a met mast's or a lidar's records) as
per-record FLORIS inputs (docs/measurements.md#a-real-mast).

``pipeline.py`` runs the stages in order, each a module a user can call and inspect:
``columns`` (1. the instruments the records hold) -> ``readings`` (2. the cleaned readings; the
vanes' part in ``vanes``) -> ``offsets`` (3. the vane offsets) -> ``record_fit`` (4. the
per-record fit) -> ``atmospheres`` (5. FLORIS's inputs per record: ``SiteAtmosphere``).
``shear_and_veer`` gives the atmosphere of FLORIS's simpler inflow inputs (a shear exponent and
a veer).

What it may import: the physics (``atmosphere/``), the plugin (``plugin/``), the energy study
(``studies/energy``) and the package's base helpers; a stage imports only the stages before it,
never ``pipeline``; nothing here imports this package's ``__init__``.
"""

from floris_ekman_veer.studies.site.atmospheres import SiteAtmosphere, SiteSummary
from floris_ekman_veer.studies.site.pipeline import fit_site
from floris_ekman_veer.studies.site.shear_and_veer import atmosphere_from_shear_and_veer

__all__ = ["SiteAtmosphere", "SiteSummary", "atmosphere_from_shear_and_veer", "fit_site"]
