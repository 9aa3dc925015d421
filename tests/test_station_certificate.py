"""The calibration certificate, rendered in a real headless Chromium (Selenium) and as PDF (WeasyPrint).

References: the numbers on the page are compared with the result file the certificate was made from
(formatted independently here), the verdicts with the file's acceptance section; the PDF with its
file signature and page count.
"""

import json
import shutil

import pytest
from cli_runner import invoke, refused


def _browser():
    from selenium import webdriver
    from selenium.webdriver.chrome.options import Options
    from selenium.webdriver.chrome.service import Service

    binary = shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")
    driver = shutil.which("chromedriver")
    assert binary and driver, "no Chromium and chromedriver on PATH: apt-get install chromium chromium-driver"
    options = Options()
    for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--window-size=1000,1600"):
        options.add_argument(arg)
    options.binary_location = binary
    return webdriver.Chrome(options=options, service=Service(driver))


@pytest.fixture(scope="module")
def calibrated(tmp_path_factory):
    folder = tmp_path_factory.mktemp("cert")
    limits = folder / "limits.toml"
    limits.write_text('guard = 2\n[limits.k]\nmin = 0.98\nmax = 1.02\n[limits.b]\nmax_abs = 2.0\nunit = "deg/s"\n')
    out = folder / "cal.json"
    code, _, err = invoke("calibrate", "--example", "-o", out, "--unit", "SN-42", "--part", "IMU-<b>7</b>",
                          "--procedure", "servo6@1.2", "--limits", limits)
    assert code == 1, err  # bx of the example is 2.54 deg/s: over the 2 deg/s limit
    return folder, json.loads(out.read_text())


def test_certificate_renders_with_the_numbers_and_verdicts(calibrated):
    folder, doc = calibrated
    page = folder / "cert.html"
    code, out, err = invoke("certificate", folder / "cal.json", "-o", page)
    assert code == 0, err
    assert "FAIL" in out
    from selenium.webdriver.common.by import By

    browser = _browser()
    try:
        browser.get(page.as_uri())
        assert browser.find_element(By.ID, "verdict").text == "FAIL"
        rows = browser.find_elements(By.CSS_SELECTOR, "#results tr")[1:]
        criteria = doc["acceptance"]["criteria"]
        assert len(rows) == len(criteria) == 6
        for row, c in zip(rows, criteria):
            cells = [td.text for td in row.find_elements(By.TAG_NAME, "td")]
            assert c["name"] in cells[0]
            assert float(cells[2]) == pytest.approx(c["value"], rel=1e-5)
            assert float(cells[3]) == pytest.approx(c["sigma"], rel=1e-2)
            assert cells[-1] == c["verdict"].upper()
        identity = browser.find_element(By.ID, "identity").text
        assert "SN-42" in identity and "IMU-<b>7</b>" in identity and "servo6 1.2" in identity  # escaped, not markup
        sha = doc["unit"]["inputs"][0]["sha256"]
        assert sha in browser.find_element(By.ID, "inputs").text
        picture = browser.find_element(By.ID, "picture")
        assert browser.execute_script("return arguments[0].complete && arguments[0].naturalWidth", picture) > 100
    finally:
        browser.quit()


def test_pdf_certificate(calibrated):
    """Reference: the PDF's text as pypdf extracts it (an independent reader)."""
    folder, doc = calibrated
    pdf = folder / "cert.pdf"
    code, _, err = invoke("certificate", folder / "cal.json", "-o", pdf)
    assert code == 0, err
    from pypdf import PdfReader

    text = "\n".join(page.extract_text() for page in PdfReader(pdf).pages)
    assert "triaxial gyroscope SN-42" in text and "Verdict: FAIL" in text
    assert f"{doc['acceptance']['criteria'][0]['value']:.6g}" in text


def test_certificate_refusals(calibrated, tmp_path):
    folder, _ = calibrated
    assert "as .html or .pdf" in refused("certificate", folder / "cal.json", "-o", tmp_path / "cert.txt")
    bare = tmp_path / "bare.json"
    code, _, _ = invoke("calibrate", "--example", "-o", bare)
    assert code == 0
    assert "no 'unit' section" in refused("certificate", bare, "-o", tmp_path / "c.html")
    assert not (tmp_path / "c.html").exists()
