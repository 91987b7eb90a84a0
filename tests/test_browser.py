"""The interactive report.html in a real browser (headless Chromium, through selenium and
Debian's chromedriver): the report of the fixture results (conftest's fixture_report),
opened from disk.

- every chart renders (plotly's SVG root in every chart), at least 8 of them;
- a study's section opens on its picture, and its static pictures load;
- the page logs no console error and requests nothing from any network;
- hovering a known workspace pose shows the frequency results.json stores for it;
- the mode viewer switches modes and moves (its vertices differ between two instants), and
  none of these interactions logs an error.

Run alone with `pytest -m browser`. Without Chromium or its driver the module is skipped,
unless RPS_REQUIRE_BROWSER=1 (as .ci/run sets it), where their absence fails.
"""
from __future__ import annotations

import json
import os
import re
import shutil
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.browser

FIXTURES = Path(__file__).resolve().parent / "fixtures"
RESULTS = FIXTURES / "report_results.json"
BROWSER = shutil.which("chromium") or shutil.which("chromium-browser")
DRIVER = shutil.which("chromedriver")
TIMEOUT_S = 90


def _require_browser() -> None:
    required = os.environ.get("RPS_REQUIRE_BROWSER") == "1"
    try:
        import selenium  # noqa: F401
    except ImportError:
        missing = "selenium is needed (the project's [test] extra)"
    else:
        missing = "" if BROWSER and DRIVER else (
            "Chromium and chromedriver are needed (apt-get install chromium chromium-driver)")
    if missing:
        (pytest.fail if required else pytest.skip)(missing)


@pytest.fixture(scope="module")
def page(fixture_report):
    _require_browser()
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.support.ui import WebDriverWait

    html = fixture_report.html
    options = webdriver.ChromeOptions()
    options.binary_location = BROWSER
    for flag in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage",
                 "--window-size=1400,1000", "--use-angle=swiftshader",
                 "--enable-unsafe-swiftshader", "--no-first-run", "--disable-extensions"):
        options.add_argument(flag)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(DRIVER), options=options)
    try:
        driver.get(html.as_uri())
        WebDriverWait(driver, TIMEOUT_S).until(
            lambda d: d.execute_script("return document.body.dataset.chartsRendered"))
        yield {"driver": driver, "html": html,
               "results": json.loads(RESULTS.read_text(encoding="utf-8")),
               "log": driver.get_log("browser")}  # what loading logged (read once: it drains)
    finally:
        driver.quit()


def test_every_chart_renders(page):
    driver = page["driver"]
    charts = driver.find_elements("css selector", ".plotly-chart")
    assert len(charts) >= 8
    assert int(driver.execute_script("return document.body.dataset.chartsRendered")) \
        == len(charts)
    for chart in charts:
        assert chart.find_elements("css selector", "svg.main-svg"), \
            chart.get_attribute("data-chart")


def test_every_study_section_opens_on_its_picture(page):
    """Each study drawn as its tables (issue 54) opens on a picture before its first table:
    its chart rendered, or its static figure loaded (a decoded image, not a broken one)."""
    driver = page["driver"]
    found = driver.execute_script("""
        const out = {};
        for (const id of ["uncertainty", "uncertainty-path"]) {
            const section = document.getElementById(id);
            if (!section) { out[id] = "missing"; continue; }
            const first = section.querySelector("figure, table");
            const chart = first && first.querySelector(".plotly-chart svg.main-svg");
            const image = first && first.querySelector("img");
            out[id] = first === null || first.tagName !== "FIGURE" ? "table first"
                : chart ? "chart" : image && image.complete && image.naturalWidth > 100
                ? "image" : "broken";
            const images = [...section.querySelectorAll("figure img")];
            if (images.some(i => !(i.complete && i.naturalWidth > 100))) out[id] = "broken";
        }
        return out;""")
    assert found == {"uncertainty": "chart", "uncertainty-path": "chart"}, found


def test_no_console_error_and_no_network_request(page):
    errors = [e for e in page["log"] if e["level"] == "SEVERE"]
    assert not errors, errors
    requested = page["driver"].execute_script(
        "return performance.getEntriesByType('resource').map(e => e.name)")
    assert not [r for r in requested if not r.startswith(("file:", "data:"))], requested


def _hover_text(driver, chart_id: str, trace: int, point: int) -> str:
    """Move the real mouse onto point `point` of trace `trace` and return the hover label."""
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.support.ui import WebDriverWait

    found = driver.execute_script("""
        const gd = document.getElementById(arguments[0]);
        gd.scrollIntoView({block: 'center'});
        const uid = gd._fullData[arguments[1]].uid;
        for (const el of gd.querySelectorAll('.trace.scatter')) {
          const points = Array.from(el.querySelectorAll('path.point'));
          const hit = points.find(p => p.__data__ && p.__data__.i === arguments[2]
                                      && el.__data__ && el.__data__[0].trace.uid === uid);
          if (hit) { return hit; }
        }
        return null;""", chart_id, trace, point)
    assert found is not None, (chart_id, trace, point)
    ActionChains(driver).move_to_element(found).pause(0.3).move_by_offset(1, 0).perform()
    WebDriverWait(driver, 10).until(
        lambda d: d.find_elements("css selector", f"#{chart_id} .hovertext"))
    return driver.find_element("css selector", f"#{chart_id} .hovertext").text


def test_hover_on_a_workspace_pose_shows_its_stored_frequency(page):
    """The pose is found in results.json from the height, tilt and azimuth the label shows,
    not from the chart's own point list, and every frequency shown is the stored one."""
    from reports.interactive_maps import map_points, valid_layers

    driver, ws = page["driver"], page["results"]["studies"]["workspace"]
    layers = valid_layers(ws)
    n = len(layers) // 2  # a middle layer; mode f1 traces are drawn first, one per layer
    p = len(map_points(ws, layers[n])) // 2 + 1  # a pose on a tilted ring
    text = _hover_text(driver, "chart-workspace_map", n, p)
    shown = re.search(r"z = ([\d.]+) mm, θ = ([\d.]+)°, φ = ([\d.]+)°", text)
    assert shown, text
    z, tilt, phi = (float(v) for v in shown.groups())
    iz = min(range(len(ws["heights_mm"])), key=lambda i: abs(ws["heights_mm"][i] - z))
    ring = min(range(len(ws["tilts_deg"][iz])), key=lambda r: abs(ws["tilts_deg"][iz][r] - tilt))
    az = min(range(len(ws["azimuths_deg"])), key=lambda a: abs(ws["azimuths_deg"][a] - phi))
    assert abs(ws["heights_mm"][iz] - z) <= 0.05 and abs(ws["tilts_deg"][iz][ring] - tilt) \
        <= 0.005 and abs(ws["azimuths_deg"][az] - phi) <= 0.05, text
    assert tilt > 0, "a tilted pose was meant"
    stored = ws["frequencies_hz"][iz][ring][az]
    for k, f in enumerate(stored):
        value = re.search(rf"f{k + 1} = ([\d.]+) Hz", text)
        assert value, text
        assert float(value.group(1)) == pytest.approx(f, abs=0.005 + 1e-9), (k, text)
    legs = re.search(r"leg lengths \(mm\): ([\d.]+), ([\d.]+), ([\d.]+)", text)
    assert legs, text
    assert [float(v) for v in legs.groups()] == pytest.approx(
        ws["actuation_mm"][iz][ring][az], abs=0.05 + 1e-9)


def test_the_mode_viewer_switches_modes_and_moves(page):
    from selenium.webdriver.support.ui import Select, WebDriverWait

    driver = page["driver"]
    viewer = driver.find_element("css selector", ".mode-viewer")
    driver.execute_script("arguments[0].scrollIntoView({block: 'center'})", viewer)
    select = Select(viewer.find_element("xpath", "preceding-sibling::div[1]//select"))
    labels = [o.text for o in select.options]
    assert len(labels) >= 2 and labels[0].startswith("FEM mode 1:")
    select.select_by_index(1)
    title = driver.execute_script("return arguments[0].layout.title.text", viewer)
    assert title == labels[1]

    def solid_x():
        return driver.execute_script(
            "const gd = arguments[0]; return Array.from(gd.data[1].x.slice(0, 50));", viewer)
    still = solid_x()
    time.sleep(0.3)
    assert solid_x() == still, "a mode moves before it is asked to"
    button = viewer.find_element("xpath", "preceding-sibling::div[1]//button")
    button.click()  # animate
    try:
        WebDriverWait(driver, 20).until(lambda d: solid_x() != still)
    finally:
        button.click()  # pause: a software-rendered scene in motion slows the browser


def test_no_console_error_after_hovering_and_animating(page):
    """Last in the module: what the interactions above logged (hover, mode switch,
    animation) has no error either."""
    errors = [e for e in page["driver"].get_log("browser") if e["level"] == "SEVERE"]
    assert not errors, errors
