"""The project's documentation holds together: every ``docs/<page>.md#anchor`` that a source,
test, input or page cites exists; every relative link and every project file path named in the
text exists in the repository; every test a page cites is defined; no file cites a document the
project does not contain; and the numbers of docs/validation.md#table-1 are what the code gives.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
DOCS = REPO / "docs"
#: The text files of the project that may cite documentation.
SOURCES = sorted(
    p for pattern in ("*.md", "*.py", "*.yaml", "*.sh", "*.toml")
    for p in REPO.rglob(pattern)
    if not any(part.startswith(".") or part in ("output", "build") for part in p.relative_to(REPO).parts)
    and "egg-info" not in str(p)
)
#: Top-level folders whose files the text may name by path.
PROJECT_FOLDERS = ("docs", "inputs", "examples", "benchmarks", "tests", "scripts", "floris_ekman_veer")


def github_anchor(heading: str) -> str:
    """GitHub's anchor of a Markdown heading: lower case, punctuation dropped, spaces to '-'."""
    text = re.sub(r"[`*]", "", heading.strip()).lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(page: Path) -> set[str]:
    found, seen, in_code = set(), {}, False
    for line in page.read_text().splitlines():
        if line.startswith("```"):
            in_code = not in_code
        if in_code:
            continue
        match = re.match(r"#{1,6}\s+(.*)", line)
        if match:
            anchor = github_anchor(match[1])
            count = seen.get(anchor, 0)
            seen[anchor] = count + 1
            found.add(anchor if count == 0 else f"{anchor}-{count}")
    return found


def relative(path: Path) -> str:
    return str(path.relative_to(REPO))


def test_github_anchor_rule():
    assert github_anchor("Lateral velocity near the ABL top") == "lateral-velocity-near-the-abl-top"
    assert github_anchor("Hub-aligned frame") == "hub-aligned-frame"
    assert github_anchor("M-3") == "m-3"
    assert github_anchor("Table 1") == "table-1"
    assert github_anchor("Which velocity goes where?") == "which-velocity-goes-where"
    assert github_anchor("`ekman_veer` models") == "ekman_veer-models"


def test_docs_have_an_index_linked_from_the_readme():
    assert (DOCS / "README.md").is_file()
    index = (DOCS / "README.md").read_text()
    for page in sorted(DOCS.glob("*.md")):
        if page.name != "README.md":
            assert f"]({page.name}" in index, f"docs/README.md does not link {page.name}"
    assert "](docs/README.md)" in (REPO / "README.md").read_text()


# docs/<page>.md#anchor, as cited in code and text (an anchor ends at whitespace or punctuation).
CITATION = re.compile(r"docs/([\w\-]+\.md)(?:#([\w\-]+))?")


def citations():
    for path in SOURCES:
        for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            for match in CITATION.finditer(line):
                yield f"{relative(path)}:{number}", match[1], match[2]


def test_cited_doc_pages_and_anchors_exist():
    cited = list(citations())
    assert len(cited) > 30  # the code cites the pages throughout; an empty scan would pass vacuously
    missing = []
    for where, page, anchor in cited:
        target = DOCS / page
        if not target.is_file():
            missing.append(f"{where}: docs/{page} does not exist")
        elif anchor and anchor.rstrip("-") not in anchors(target):
            missing.append(f"{where}: docs/{page}#{anchor} has no such heading (add the section "
                           "to the page, or cite an existing one)")
    assert not missing, "\n".join(missing)


MARKDOWN_LINK = re.compile(r"\]\(([^)\s]+)\)")


def test_relative_links_in_markdown_resolve():
    broken = []
    for path in SOURCES:
        if path.suffix != ".md":
            continue
        for target in MARKDOWN_LINK.findall(path.read_text()):
            if re.match(r"[a-z]+:", target):  # http:, https:, mailto:
                continue
            file_part, _, anchor = target.partition("#")
            resolved = (path.parent / file_part).resolve() if file_part else path
            if REPO not in resolved.parents and resolved != REPO:
                broken.append(f"{relative(path)}: {target} leaves the repository")
            elif not resolved.exists():
                broken.append(f"{relative(path)}: {target} does not exist")
            elif anchor and resolved.suffix == ".md" and anchor not in anchors(resolved):
                broken.append(f"{relative(path)}: {target} has no such heading")
    assert not broken, "\n".join(broken)


PROJECT_PATH = re.compile(
    r"(?<![\w/.])((?:%s)/[\w./\-]*\.(?:py|md|yaml|yml|sh|png|toml))" % "|".join(PROJECT_FOLDERS)
)


def test_project_paths_named_in_the_text_exist():
    missing = []
    for path in SOURCES:
        for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            for name in PROJECT_PATH.findall(line):
                if not (REPO / name).exists():
                    missing.append(f"{relative(path)}:{number}: {name}")
    assert not missing, "\n".join(missing)


# Documents of the project's development that are not part of it, and paths of one machine.
# (the first name is spelt in two pieces so that this line does not cite it itself)
OUTSIDE = re.compile("|".join(["MODEL" "_NOTES", r"ARCHITECTURE\.md", "/work/", "/home/", "/Users/"]))


def test_nothing_cites_a_document_outside_the_project():
    offending = [
        f"{relative(path)}:{number}: {line.strip()}"
        for path in SOURCES
        if path != Path(__file__).resolve()
        for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1)
        if OUTSIDE.search(line)
    ]
    assert not offending, "\n".join(offending)


def test_tests_cited_by_the_docs_exist():
    defined = set()
    for path in (REPO / "tests").rglob("test_*.py"):
        defined.update(re.findall(r"^\s*def (test_\w+)", path.read_text(), flags=re.M))
    cited = {
        (page.name, name)
        for page in DOCS.glob("*.md")
        for name in re.findall(r"`(test_\w+)`", page.read_text())
    }
    assert len(cited) > 20
    missing = sorted(f"docs/{page} cites {name}, which no test defines: update the page to what "
                     "the tests pin now" for page, name in cited if name not in defined)
    assert not missing, "\n".join(missing)


# ------------------------------------------------------------------------ docs/validation.md#table-1
def table_rows(heading: str, page: str = "validation.md"):
    """(header, rows) of the first table under ``heading`` in ``docs/<page>``."""
    lines = (DOCS / page).read_text().splitlines()
    start = next(i for i, line in enumerate(lines) if line.strip() == heading)
    rows, in_table = [], False
    for line in lines[start + 1:]:
        if line.startswith("|"):
            in_table = True
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if not set("".join(cells)) <= set("-: "):
                rows.append(cells)
        elif in_table:
            break
    return rows[0], rows[1:]


PAPER = dict(geostrophic_wind=15.0, roughness_length=0.1, coriolis_parameter=1e-4,
             brunt_vaisala_frequency=6.1e-3, reference_potential_temperature=265.0)
#: The paper's Table 1: mu, C_r [K/h].
TABLE1_INPUTS = {"CNBL": (0.0, 0.0), "SBL-1": (5.62, -0.03), "SBL-2": (20.59, -0.125),
                 "SBL-3": (39.84, -0.25), "SBL-4": (59.25, -0.375), "SBL-5": (78.35, -0.5),
                 "SBL-6": (148.49, -1.0)}


def test_validation_table1_is_what_the_model_gives():
    from floris_ekman_veer.atmosphere.ekman import EkmanABL

    header, rows = table_rows("## Table 1")
    assert [r[0] for r in rows] == list(TABLE1_INPUTS)
    column = {name: i for i, name in enumerate(header)}
    checked = 0
    for row in rows:
        mu, c_r = TABLE1_INPUTS[row[0]]
        for closure, value in (("mu", dict(stability_parameter=mu)), ("C_r", dict(cooling_rate=c_r))):
            abl = EkmanABL(**PAPER, **value)
            got = {
                f"h [m] ({closure})": abl.boundary_layer_height,
                f"u* [m/s] ({closure})": abl.friction_velocity,
                f"alpha_0 [deg] ({closure})": abl.cross_isobaric_angle,
                f"mu ({closure})": abl.stability_parameter,
                f"veer 50-150 m [deg] ({closure})": abl.wind_direction_change(50.0, 150.0),
            }
            for name, value in got.items():
                if name in column:
                    assert_printed(row[column[name]], float(value), (row[0], name))
                    checked += 1
    assert checked >= 7 * 8


def assert_printed(text: str, value: float, where) -> None:
    """``text`` is ``value`` rounded to the digits printed (half a unit of the last digit)."""
    decimals = len(text.partition(".")[2])
    assert abs(float(text) - value) <= 0.51 * 10.0**-decimals, (where, text, value)


@pytest.mark.parametrize("page", ["conventions.md", "atmosphere.md", "wake_model.md",
                                  "coupling.md", "validation.md"])
def test_pages_exist_and_cite_the_paper_by_equation(page):
    text = (DOCS / page).read_text()
    assert re.search(r"Eqs?\. \(\w+\)", text), f"docs/{page} cites no equation of the paper"


def test_validation_single_wakes_are_what_the_model_gives():
    """The paper's disk (C_T' = 1.33, D = z_h = 100 m) at zero yaw, cooling-rate closure."""
    from floris_ekman_veer.atmosphere.ekman import EkmanABL
    from floris_ekman_veer.wake import deficit

    ct_prime, radius, hub = 1.33, 50.0, 100.0
    ct = 16.0 * ct_prime / (4.0 + ct_prime) ** 2
    header, rows = table_rows("## Single wakes")
    assert [r[0] for r in rows] == ["CNBL", "SBL-4", "SBL-5", "SBL-6"]
    for row in rows:
        abl = EkmanABL(**PAPER, cooling_rate=TABLE1_INPUTS[row[0]][1])
        k_w = float(abl.wake_expansion_rate(hub))
        got = {
            "I_u(z_h)": abl.turbulence_intensity(hub),
            "k_w": k_w,
            "x0/D": deficit.potential_core_length(k_w, radius, ct, 0.0) / (2 * radius),
            "C(5 D)": deficit.max_deficit(10 * radius, k_w, radius, ct, 0.0),
            "C(10 D)": deficit.max_deficit(20 * radius, k_w, radius, ct, 0.0),
        }
        assert header[1:] == list(got)
        for i, value in enumerate(got.values(), 1):
            assert_printed(row[i], float(value), (row[0], header[i]))


def test_atmosphere_backing_layer_table_is_what_the_model_gives():
    """docs/atmosphere.md#lateral-velocity-near-the-ground: where V > 0 and its maximum."""
    import numpy as np

    from floris_ekman_veer.atmosphere.ekman import EkmanABL

    _, rows = table_rows("## Lateral velocity near the ground", "atmosphere.md")
    assert [r[0] for r in rows] == ["CNBL", "SBL-4", "SBL-6"]
    for case, h_text, top_text, peak_text in rows:
        abl = EkmanABL(**PAPER, cooling_rate=TABLE1_INPUTS[case][1])
        h = float(abl.boundary_layer_height)
        z = np.linspace(1.0, h, 200_001)
        v = abl.velocity(z)[1]
        top = z[np.argmax(v < 0)]  # first height above 1 m with V < 0
        peak = np.argmax(v)
        speed, height = re.match(r"\+([\d.]+) m/s at (\d+) m", peak_text).groups()
        assert_printed(h_text, h, case)
        assert_printed(top_text, top, case)
        assert_printed(speed, v[peak], case)
        assert_printed(height, z[peak], case)
        assert 0.26 < top / h < 0.30


# ------------------------------------------------------------------------- citations of the paper
#: Equation labels of Narasimhan, Gayme & Meneveau (JRSE 2025), as in its LaTeX source. ``GDL``
#: stands for the label ``eqn:GDL`` and ``eqn:avoidnumbers1a``/``b`` for the two parts of
#: ``eqn:avoidnumbers1`` (g and g').
PAPER_EQUATIONS = {
    "du_model", "Cx", "sigma_tilde", "A_star", "ind_factor", "x0_transition", "sigma_width",
    "polar_angle", "wake_shape_function", "xi0_theta", "xi_emp", "that", "upup_var", "Iu_model",
    "kw_model_high_Iu", "kw_CNBL_SBL_model", "yc_xz", "yhatc", "yc_veer", "U_vel", "V_vel",
    "eqn:avoidnumbers1", "eqn:avoidnumbers1a", "eqn:avoidnumbers1b", "h_hat_model", "GDL",
    "eqn:GDL", "A_model_GDL", "B_model_GDL", "eps_z", "eps_y", "P0_ref", "P_hyp", "Ud", "P_ratio",
    "eps_P",
}
#: The paper's sections and subsections.
PAPER_SECTIONS = {"1", "2", "2.1", "2.2", "2.3", "2.4", "2.5", "3", "3.1", "4", "4.1", "4.2",
                  "4.3", "4.3.1", "4.3.2", "4.4", "5"}

EQUATION_CITATION = re.compile(r"Eqs?\.\s*((?:\([\w:]+\)(?:,\s*|\s+and\s+|\s+to\s+)?)+)")


def test_cited_equations_and_sections_are_the_papers():
    wrong, cited = [], 0
    for path in SOURCES:
        if path == Path(__file__).resolve():
            continue
        text = path.read_text(errors="replace")
        for group in EQUATION_CITATION.findall(text):
            cited += group.count("(")
            wrong += [f"{relative(path)}: Eq. ({label})" for label in re.findall(r"\(([\w:]+)\)", group)
                      if label not in PAPER_EQUATIONS]
        wrong += [f"{relative(path)}: Section {number}"
                  for number in re.findall(r"\bSections? (\d+(?:\.\d+)*)", text)
                  if number not in PAPER_SECTIONS]
    assert cited > 100  # the code cites the paper's equations throughout
    assert not wrong, "\n".join(wrong)


def test_docs_index_lists_every_model_equation():
    """docs/README.md's equation table has a row for each equation of the paper's model (the
    error measures against the LES, eps_*, are named in the text below it)."""
    index = (DOCS / "README.md").read_text()
    rows = {re.match(r"\|\s*([\w:]+)", line)[1] for line in index.splitlines()
            if re.match(r"\|\s*[\w:]+\s*(\([\w:]+\)\s*)?\|\s*\d", line)}
    model = {label for label in PAPER_EQUATIONS
             if not label.startswith(("eps_", "eqn:avoidnumbers1a", "eqn:avoidnumbers1b", "eqn:GDL"))}
    assert model <= rows, sorted(model - rows)


def test_readme_quick_start_fits_a_screen_and_links_the_gallery():
    """The README is a one-screen quick start: the two set-up commands .ci/run reads, a gallery
    of committed figures written by the examples, and the detail in docs/."""
    text = (REPO / "README.md").read_text()
    assert len(text.splitlines()) < 250
    for marker in ("<!-- main-command -->", "<!-- test-command -->"):
        assert marker in text
    figures = re.findall(r"!\[[^\]]*\]\((docs/[\w\-]+\.png)\)", text)
    assert len(figures) >= 4 and all((REPO / f).is_file() for f in figures)
    # each figure is written by an example run with --gallery docs, named next to it
    scripts = re.findall(r"python (examples/\w+\.py) --gallery docs", text)
    assert len(set(scripts)) >= 4
    for script in scripts:
        assert "--gallery" in (REPO / script).read_text(), script


def test_user_guide_lists_every_example():
    """docs/user_guide.md#examples names every script of examples/, with what it does."""
    text = (REPO / "docs" / "user_guide.md").read_text()
    section = text.split("\n## Examples\n", 1)[1].split("\n## ", 1)[0]
    listed = set(re.findall(r"^- `examples/(\w+)\.py`", section, flags=re.M))
    assert listed == {p.stem for p in (REPO / "examples").glob("*.py")}


# ------------------------------------------------------------ numbers the pages take from scripts
#: Numbers of the README and docs/ that a named script prints: (page, the page's text holding
#: the number, the script and its arguments, a regular expression of the script's output whose
#: groups are the number(s) the page's text holds, in the page's order). A page that changes its
#: text, or a script whose output moves, fails here; each script runs once (marker study: they are the
#: examples themselves, run by .ci/run after the fast suite).
SCRIPT_NUMBERS = [
    ("README.md", r"P/P0 = ([\d.]+) with M-1, against ([\d.]+) with M-2 and M-3 and ([\d.]+) and "
                  r"([\d.]+) with FLORIS's GCH and cc on the same inflow",
     ("examples/paper_power.py",),
     r"beta = \+0 deg.*?SBL-6\s+M-1(?:\s+\S+ \(\S+\)){3}\s+([\d.]+) .*?SBL-6\s+M-2(?:\s+\S+ \(\S+\)){3}"
     r"\s+([\d.]+) .*?SBL-6\s+GCH(?:\s+\S+ \(\S+\)){3}\s+([\d.]+) .*?SBL-6\s+cc(?:\s+\S+ \(\S+\)){3}"
     r"\s+([\d.]+) "),
    ("README.md", r"in CNBL, without veer, M-1, M-2 and M-3 agree \(([\d.]+)\)",
     ("examples/paper_power.py",),
     r"beta = \+0 deg.*?CNBL\s+M-1(?:\s+\S+ \(\S+\)){3}\s+([\d.]+) "),
    ("docs/measurements.md", r"\| zero reading \| (\d+) \| \| calm \| (\d+) \| \| backing \| "
                             r"(\d+) \| \| no top \| (\d+) \| \| misfit \| (\d+) \| \| physical "
                             r"bound \| (\d+) \| \| fitted \| (\d+) \|",
     ("examples/site_year.py",),
     r"zero reading\s+(\d+) .*?calm\s+(\d+) .*?backing\s+(\d+) .*?no top\s+(\d+) .*?"
     r"misfit\s+(\d+) .*?physical bound\s+(\d+) .*?fitted\s+(\d+) "),
    ("docs/measurements.md", r"It keeps [\d,]+ of the 8,760 records, ([\d.]+) % of the records the "
                             r"generator made not calm .*? the fitted class is the generator's for "
                             r"([\d.]+) % of them .*? the vane offsets found are ([\-+][\d.]+) \+- "
                             r"[\d.]+ and ([\-+][\d.]+) \+-",
     ("examples/site_report.py", "--no-energy"),
     r"against the generator's truth: ([\d.]+) % of the non-calm records "
     r"kept; fitted class the generator's for ([\d.]+) %.*?38 m ([\-+][\d.]+) .*?58 m "
     r"([\-+][\d.]+) "),
    ("docs/measurements.md", r"\| convective \| no \| (\d+) \| (\d+) \| (\d+) \| (\d+) \| ([\d.]+) % "
                             r"\| (\d+) of 200 \| (\d+) of 200 \|",
     ("benchmarks/fit_stability_classes.py",),
     r"published forms: convective class .*? <= 20 % in \d+ of 200.*?\n  convective convective\s+"
     r"(\d+)\s+neutral\s+(\d+)\s+stable\s+(\d+)\s+refused (\d+)\s+max error ([\d.]+) %"),
    ("docs/measurements.md", r"\| convective \| no \| \d+ \| \d+ \| \d+ \| \d+ \| [\d.]+ % "
                             r"\| (\d+) of 200 \| (\d+) of 200 \|",
     ("benchmarks/fit_stability_classes.py",),
     r"published forms: convective class .*? <= 20 % in (\d+) of 200, largest [\d.]+ %; Panofsky "
     r"inside the fit's two-sigma interval in (\d+);"),
    ("docs/measurements.md", r"z_i = 1000 m puts (\d+) within 20 % .*? with the fitted u\* and the "
                             r"true L (\d+), with the true u\* and the fitted L (\d+), as fitted "
                             r"(\d+), and fitted without the noise (\d+)\. The median fitted L is "
                             r"([\d.]+) times",
     ("benchmarks/fit_stability_classes.py",),
     r"model law at the true state (\d+), fitted u\* with true L (\d+), true u\* with fitted L "
     r"(\d+), fitted (\d+), fitted without noise (\d+); median fitted L / true L ([\d.]+)"),
    ("docs/measurements.md", r"z_i fixed at 700, 1500 and 2500 m \(Panofsky's still at 1000 m\) "
                             r"the fits put (\d+) \(median misfit ([\d.]+)\), (\d+) \(([\d.]+)\) "
                             r"and (\d+) \(([\d.]+)\) of the 200 within 20 %",
     ("benchmarks/fit_stability_classes.py",),
     r"700 m: (\d+) within 20 %, median misfit ([\d.]+), 1500 m: (\d+) within 20 %, median "
     r"misfit ([\d.]+), 2500 m: (\d+) within 20 %, median misfit ([\d.]+)"),
    ("docs/measurements.md", r"accepted convective fits is ([\d.]+) % without and ([\d.]+) % with "
                             r"the measured I_u",
     ("benchmarks/fit_stability_classes.py",),
     r"accepted at hub >= 6 m/s ([\d.]+) %.*?accepted at hub >= 6 m/s ([\d.]+) %"),
    ("docs/measurements.md", r"\| ekman_veer \| ([\d.]+) \| ([\d.]+) \| ([+\-][\d.]+) % \|",
     ("examples/site_fit.py",),
     r"ekman_veer\s+([\d.]+)\s+([\d.]+)\s+([+\-]?[\d.]+)"),
]
SCRIPT_NUMBERS += [
    ("docs/atmosphere.md", r"differs from the paper's CNBL by \+([\d.]+) % in u\* and h, ([\d.]+) % in U "
                           r"and ([\d.]+) % in V \(of the 8 m/s, over 1-1000 m\) and \+([\d.]+) % in k_w",
     ("examples/day_and_night.py",),
     r"At L = -1e5 m against the CNBL.*?u\* \+([\d.]+) %, h \+[\d.]+ %, U \+([\d.]+) %, "
     r"V \+([\d.]+) %, k_w \+([\d.]+) %"),
]
#: The README's own results (docs/performance.md's timings: test_readme_timings_say_how_measured).
SCRIPT_NUMBERS += [
    ("README.md", r"\| 8 m/s \| ([\d.]+) \| ([\d.]+) \| ([\d.]+) \| \| 9 m/s \| ([\d.]+) \| ([\d.]+) \| "
                  r"([\d.]+) \| \| 11 m/s \| ([\d.]+) \| ([\d.]+) \| ([\d.]+) \|",
     ("examples/farm_main.py",),
     r"U\(90 m\) = 8 m/s.*?farm \[MW\]\s+([\d.]+)\s+([\d.]+)\s+([\d.]+).*?U\(90 m\) = 9 m/s.*?"
     r"farm \[MW\]\s+([\d.]+)\s+([\d.]+)\s+([\d.]+).*?U\(90 m\) = 11 m/s.*?farm \[MW\]\s+"
     r"([\d.]+)\s+([\d.]+)\s+([\d.]+)"),
    ("README.md", r"M-1 misses the power ratios P_i/P_1 of rows 2-10 by ([\d.]+) RMSE, FLORIS's GCH "
                  r"by ([\d.]+) and the published EllipSys3D RANS by ([\d.]+), and FLORIS's "
                  r"`empirical_gauss` by as little \(([\d.]+)\)",
     ("examples/validate.py",),
     # the matched atmosphere, direction-averaged: the third cell of each model's row
     r"## Hornsrev1, P_i/P_1 over the waked positions[^\n]*\n"
     + "".join(rf"(?=.*?\n\| {model} \|(?:[^|]+\|){{2}} ([\d.]+))"
               for model in ("M-1", "GCH", r"EllipSys3D RANS \(published\)", "empirical_gauss"))),
    ("README.md", r"M-1 misses by ([\d.]+), GCH by ([\d.]+), the RANS by ([\d.]+), FLORIS's cc by "
                  r"([\d.]+) and\s+TurbOPark by ([\d.]+)",
     ("examples/validate.py",),
     r"## Lillgrund, P_i/P_1 over the waked positions[^\n]*\n"
     + "".join(rf"(?=.*?\n\| {model} \|(?:[^|]+\|){{2}} ([\d.]+))"
               for model in ("M-1", "GCH", r"EllipSys3D RANS \(published\)", "cc", "TurbOPark"))),
]
#: docs/atmosphere.md's drag-law table, row by row: L's label, then the nine numbers.
SCRIPT_NUMBERS += [
    ("docs/atmosphere.md", rf"\| {label} \|" + r" (-?[\d.]+) \|" * 9, ("examples/day_and_night.py",),
     rf"Drag-law coefficients.*?\n\s+{label}" + r"\s+(-?[\d.]+)" * 9)
    for label in ("-1e5", "-1e4", "-1000", "-300", "-100", "-30")
]


#: The README's measured times and speed ratios (they move with the machine, so no test can
#: re-measure them): each names the command that measured it, the load it ran at and the
#: threads (docs/performance.md has the tables; the README's test-command sentence is the
#: lead's and is checked by .ci/run).
README_TIMINGS = [
    (r"a steered year of 8,760 records on a 3 x 3 farm takes ([\d.]+) minutes",
     "python -m benchmarks.bench_year"),
    (r"M-1 runs at ([\d.]+) x FLORIS gauss's wall time", "python -m benchmarks.bench_peers"),
]


@pytest.mark.parametrize("claim, command", README_TIMINGS)
def test_readme_timings_say_how_measured(claim, command):
    text = re.sub(r"\s+", " ", (REPO / "README.md").read_text())
    match = re.search(claim, text)
    assert match, f"README.md no longer holds {claim!r}: update README_TIMINGS"
    paragraph = text[match.start():match.start() + 700]
    assert command in paragraph
    assert re.search(r"load average [\d.]+(-[\d.]+)? on the 2 cores", paragraph)
    assert "thread" in paragraph


def page_numbers(page: str, pattern: str) -> list[str]:
    match = re.search(pattern, re.sub(r"\s+", " ", (REPO / page).read_text()))
    assert match, f"{page} no longer holds the text {pattern!r}: update SCRIPT_NUMBERS with it"
    return list(match.groups())


@pytest.mark.parametrize("page, text, script, output", SCRIPT_NUMBERS,
                         ids=[f"{p}:{s[0]}" for p, _, s, _ in SCRIPT_NUMBERS])
def test_pages_hold_the_texts_their_scripts_are_compared_with(page, text, script, output):
    assert page_numbers(page, text)
    assert (REPO / script[0]).is_file()


_SCRIPT_OUTPUT: dict = {}


def script_output(script, tmp_path_factory) -> str:
    import os
    import subprocess
    import sys

    if script not in _SCRIPT_OUTPUT:
        env = {**os.environ, "MPLBACKEND": "Agg"}  # the scripts import the installed package
        run = subprocess.run([sys.executable, str(REPO / script[0]), *script[1:]],
                             cwd=tmp_path_factory.mktemp("script"), env=env, capture_output=True,
                             text=True, timeout=1800)
        assert run.returncode == 0, run.stderr[-3000:]
        _SCRIPT_OUTPUT[script] = run.stdout
    return _SCRIPT_OUTPUT[script]


@pytest.mark.study
@pytest.mark.parametrize("page, text, script, output", SCRIPT_NUMBERS,
                         ids=[f"{p}:{s[0]}" for p, _, s, _ in SCRIPT_NUMBERS])
def test_page_numbers_are_what_their_scripts_print(page, text, script, output, tmp_path_factory):
    printed = re.search(output, script_output(script, tmp_path_factory), flags=re.S)
    assert printed, f"{script[0]} no longer prints {output!r}"
    written = page_numbers(page, text)
    got = [g for g in printed.groups()]
    assert len(got) <= len(written)
    for text_value, value in zip(written, got):
        decimals = len(text_value.partition(".")[2])
        assert abs(float(text_value) - float(value)) <= 0.51 * 10.0**-decimals, \
            (page, text_value, script[0], value)
