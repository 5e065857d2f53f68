"""The site fit: a site's measured wind profiles (a met mast's or a lidar's records) as
per-record FLORIS inputs (docs/measurements.md#a-real-mast).

``pipeline.py`` (``fit_site``) runs the stages in order, each a module a user can call and
inspect: ``columns`` (1. the instruments the records hold; ``wra_file`` reads them from the mast's
IEA Wind Task 43 metadata file) -> ``readings`` (2. the cleaned readings; the vanes' part in
``vanes``) -> ``baseline`` and ``offsets`` (3. the site's neutral baseline and the vane offsets)
-> ``record_fit`` (4. the per-record fit) -> ``atmospheres`` (5. FLORIS's inputs per record:
``SiteAtmosphere``, ``SiteSummary``). ``shear_and_veer`` gives the atmosphere of FLORIS's simpler
inflow inputs (a shear exponent and a veer).

What it may import: the physics (``atmosphere/``), the plugin (``plugin/``), the energy study
(``studies/energy/``) and the package's base helpers; a stage imports only the stages before it
and the helpers (``vanes``), never ``pipeline``.
"""
