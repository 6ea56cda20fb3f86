"""The documentation site as a reader sees it: the start page and the API reference opened in
headless Chromium, each screenshot read back by OCR (tesseract). On each the page's title (its
<h1>, from the HTML) must be legible, and so must a code block's text: on the start page a
line of its first C program, on the API page a declaration (ga_version_number). Then Chromium's
rendered DOM must hold what the screenshot shows (the title and a code block) -- so a page
that renders blank, unstyled or cut off fails.

Usage: check_site.py HTML_DIR SCREENSHOT_DIR"""
import html
import os
import re
import shutil
import subprocess
import sys
import tempfile

CHROMIUM = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
            "--disable-background-networking", "--disable-component-update", "--disable-sync",
            "--hide-scrollbars", "--force-device-scale-factor=2"]


def chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    raise SystemExit("no chromium (Debian: apt-get install chromium)")


def browse(page, args, profile):
    done = subprocess.run([chromium(), *CHROMIUM, "--user-data-dir=" + profile, *args,
                           "file://" + os.path.abspath(page)], capture_output=True, text=True,
                          timeout=120)
    if done.returncode != 0:
        raise SystemExit("chromium failed on %s:\n%s" % (page, done.stderr[-2000:]))
    return done.stdout


def words(text):
    return re.findall(r"[A-Za-z_][A-Za-z_0-9]*", text)


def check(page, shots, code_line, height):
    title = html.unescape(re.search(r"<h1>(.*?)<a class=\"headerlink\"", open(page).read(),
                                    re.S).group(1)).strip()
    name = os.path.splitext(os.path.basename(page))[0]
    shot = os.path.join(shots, name + ".png")
    with tempfile.TemporaryDirectory() as profile:
        browse(page, ["--screenshot=" + shot, "--window-size=1200,%d" % height], profile)
        dom = browse(page, ["--dump-dom"], profile)
    ocr = subprocess.run(["tesseract", shot, "-", "--psm", "3"], capture_output=True,
                         text=True, check=True).stdout
    seen = set(words(ocr))
    problems = []
    if not set(words(title)) <= seen:
        problems.append("title %r not legible (OCR saw: %s)" % (title, " ".join(sorted(seen))[:400]))
    missing = [w for w in words(code_line) if w not in seen]
    if missing:
        problems.append("code line %r: %s not legible" % (code_line, ", ".join(missing)))
    if "<h1>" + html.escape(title, quote=False) not in dom and title not in html.unescape(dom):
        problems.append("the rendered DOM lacks the title")
    if not re.search(r'class="[^"]*(highlight|sig)[^"]*"', dom):
        problems.append("the rendered DOM has no code block")
    if problems:
        raise SystemExit("%s: %s (screenshot %s)" % (page, "; ".join(problems), shot))
    print("%s: title %r and code %r legible on the screenshot %s" % (
        os.path.basename(page), title, code_line, shot))


def main():
    site, shots = sys.argv[1:3]
    os.makedirs(shots, exist_ok=True)
    check(os.path.join(site, "index.html"), shots, "if (ga_create(2, 1, &s) != GA_OK) return 1;",
          2600)
    check(os.path.join(site, "api.html"), shots, "int ga_version_number(void)", 2400)


if __name__ == "__main__":
    main()
