#!/usr/bin/env python3
"""The operator's console in a real browser (issue 70, item 5): `projbot run --sim --headless --console`
with a token, driven by headless Chromium through chromedriver (Debian's chromium, chromium-driver and
python3-selenium). The page loads and shows the map with the targets and the robot, which moves from one
stop to the next, and the tour's table as it grows; the projector's frame and the camera's view arrive as pictures; the blackout button is
refused until the token is typed, then blanks the projector (the page's own picture of the projector goes
black, and the engine's closing line gives the time from the request to the first black frame); the B
key releases it. A screenshot of the page is kept in the output folder.

    python3 tests/console_browser_test.py --exe build/ci/tools/projbot --out DIR

Exit 0: passed; 1: failed, saying what; 77: skipped (no Chromium, chromedriver or Selenium here)."""
import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
import urllib.request

TOKEN = "a-browser-test-token-0123456789"


def fail(why, run=None):
    print("console browser test FAILED: " + why)
    if run is not None:
        run.send_signal(signal.SIGINT)
        print((run.communicate(timeout=60)[0] or "")[-3000:])
    sys.exit(1)


def wait(what, check, limit_s, run):
    end = time.monotonic() + limit_s
    while time.monotonic() < end:
        value = check()
        if value:
            return value
        time.sleep(0.1)
    fail(f"{what} within {limit_s} s", run)


def start_run(exe, out):
    token = os.path.join(out, "token")
    with open(os.open(token, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600), "w") as f:
        f.write(TOKEN + "\n")
    os.chmod(token, 0o600)
    log = open(os.path.join(out, "run.log"), "w+")
    run = subprocess.Popen([exe, "run", "--sim", "--headless", "--depth-model", "kinect", "--visits", "3", "--dwell", "6",
                            "--console", "127.0.0.1:0", "--console-token", token],
                           stdout=log, stderr=subprocess.STDOUT, text=True, cwd=out)

    def url():
        log.seek(0)
        m = re.search(r"console: (http://127\.0\.0\.1:\d+/)", log.read())
        return m.group(1) if m else None
    return run, log, wait("the console's address in run's output", url, 90, run)


def browser():
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    options = webdriver.ChromeOptions()
    options.binary_location = shutil.which("chromium")
    for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--window-size=1280,1150"):
        options.add_argument(a)
    return webdriver.Chrome(service=Service(shutil.which("chromedriver")), options=options)


# The page's own picture of the projector's frame: its size and how many of its pixels carry light, read
# through a canvas (the picture is a blob of this page's origin).
LIT_PIXELS = """
const img = document.getElementById('frame');
if (!img.complete || img.naturalWidth === 0) return null;
const c = document.createElement('canvas'); c.width = img.naturalWidth; c.height = img.naturalHeight;
const g = c.getContext('2d'); g.drawImage(img, 0, 0);
const d = g.getImageData(0, 0, c.width, c.height).data;
let lit = 0; for (let i = 0; i < d.length; i += 4) if (d[i] | d[i + 1] | d[i + 2]) ++lit;
return [img.naturalWidth, lit];"""


def check_page(driver, base, run):
    from selenium.webdriver.common.by import By
    text = lambda id: driver.find_element(By.ID, id).text
    driver.get(base)
    wait("the page showing a lit target", lambda: text("phase") == "lit", 120, run)
    circles = driver.execute_script("return document.querySelectorAll('#map circle').length;")
    if circles < 2:
        fail(f"the map shows {circles} targets, expected the tour's 2", run)
    wait("the tour's table with the first visit", lambda: driver.execute_script(
        "const r = document.querySelector('#tour tr'); return r && r.textContent.includes('duck');"), 10, run)
    # The map is drawn anew with each state: read it afresh each time.
    robot = lambda: driver.execute_script("const r = document.getElementById('robot'); return r && r.getAttribute('points');")
    robot_at = wait("the robot on the map", robot, 5, run)
    wait("the projector's and the camera's pictures", lambda: driver.execute_script(
        "return ['frame', 'camera'].every((k) => document.getElementById(k).naturalWidth === 320);"), 15, run)
    lit = wait("a picture of the projector's frame with light in it",
               lambda: (lambda p: p if p and p[1] > 100 else None)(driver.execute_script(LIT_PIXELS)), 10, run)

    driver.find_element(By.ID, "blackout").click()  # no token typed: refused, and the page says why
    wait("the page saying the blackout needs the token", lambda: "token" in text("said"), 5, run)
    state = json.load(urllib.request.urlopen(base + "api/state", timeout=5))
    if state["blackout"]:
        fail("the blackout was taken without the token", run)
    driver.find_element(By.ID, "token").send_keys(TOKEN)
    driver.find_element(By.ID, "blackout").click()
    wait("the page showing the blackout", lambda: "BLACKOUT" in text("flags"), 5, run)
    wait("the projector's picture going black", lambda: (lambda p: p and p[1] == 0)(driver.execute_script(LIT_PIXELS)), 5, run)
    driver.find_element(By.TAG_NAME, "body").send_keys("b")  # the key releases it
    wait("the blackout released by the B key", lambda: "BLACKOUT" not in text("flags"), 5, run)
    wait("the robot moving to its next stop on the map",
         lambda: robot() not in (None, robot_at), 90, run)
    wait("the page showing the next stop's target lit", lambda: text("phase") == "lit", 90, run)
    time.sleep(1.5)  # the pictures of the new stop (two a second) before the screenshot
    return lit


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--exe", required=True, help="the projbot executable")
    ap.add_argument("--out", required=True, help="a folder for the run's log, its token and the page's screenshot")
    a = ap.parse_args()
    try:
        import selenium  # noqa: F401
    except ImportError:
        print("console_browser_test: SKIPPED: python3-selenium is not installed (tools/setup-debian.sh installs it)")
        return 77
    if not shutil.which("chromium") or not shutil.which("chromedriver"):
        print("console_browser_test: SKIPPED: chromium or chromedriver is not installed (tools/setup-debian.sh installs them)")
        return 77
    os.makedirs(a.out, exist_ok=True)
    run, log, base = start_run(os.path.abspath(a.exe), a.out)
    driver = browser()
    try:
        lit = check_page(driver, base, run)
        shot = os.path.join(a.out, "console.png")
        driver.save_screenshot(shot + ".partial.png")
        os.replace(shot + ".partial.png", shot)
    finally:
        driver.quit()
    run.send_signal(signal.SIGINT)
    run.wait(timeout=60)
    log.seek(0)
    out = log.read()
    m = re.search(r"console: (\d+) frames blacked out; from each blackout's request to its first black frame's display: ([\d.]+) ms", out)
    if not m or int(m.group(1)) == 0:
        fail("run's closing line counts no black frame:\n" + out[-2000:])
    latency_ms = float(m.group(2))
    if not 0.0 < latency_ms < 250.0:  # the goal (one frame + 5 ms) is a measured figure; here, that it took effect
        fail(f"the blackout took {latency_ms} ms from the request to its first black frame")
    print(f"console browser test: passed; the projector's picture {lit[0]} px wide with {lit[1]} lit pixels, "
          f"blackout {latency_ms} ms from the click's request to its first black frame; screenshot {shot}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
