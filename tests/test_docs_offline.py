"""/docs (Swagger UI) renders offline: its page references only the service's own URLs, its script and style come from
the installed fastapi-offline package, and a real headless Chromium (Debian's, driven by Playwright; skipped where
either is missing) draws the operations with every request off loopback blocked. ReDoc is off (its bundle fetches its
logo from a CDN)."""

from __future__ import annotations

import re
from urllib.parse import urljoin, urlsplit

import browser
import pytest
from golfflight.service.api.routes.docs import ASSETS_DIR
from golfflight.service.app import create_app
from golfflight.service.settings import ServiceSettings
from servers import running

KEY = "docs-test-key"
CONTENT_TYPES = {".js": "text/javascript", ".css": "text/css", ".png": "image/png"}
LOCAL_HOSTS = {"127.0.0.1"}


@pytest.fixture(scope="module")
def open_service():
    """A service without an API key (a simulator bay's usual setup)."""
    with running(create_app(ServiceSettings())) as http:
        yield http


def referenced_urls(html: str) -> list[str]:
    """Every URL the docs page names: src and href attributes, and the OpenAPI document Swagger UI loads."""
    urls = re.findall(r"""(?:src|href)\s*=\s*["']([^"']+)["']""", html)
    urls += re.findall(r"""\burl:\s*["']([^"']+)["']""", html)
    return urls


def test_the_docs_page_names_only_local_urls_that_are_served(open_service):
    http = open_service
    answer = http.get("/docs")
    assert answer.status_code == 200 and answer.headers["content-type"].startswith("text/html")
    html = answer.text
    assert not re.search(r"(?:https?:)?//(?!127\.0\.0\.1[:/])[\w.-]+", html), "a URL to another host"
    urls = referenced_urls(html)
    assert "/openapi.json" in urls
    assets = [url for url in urls if urlsplit(url).path.rsplit(".", 1)[-1] in ("js", "css", "png")]
    assert len(assets) == 3, urls  # script, style, favicon
    for url in urls:
        assert url.startswith("/") and not url.startswith("//"), url
        served = http.get(url)
        assert served.status_code == 200, url
        if url in assets:
            suffix = "." + url.rsplit(".", 1)[-1]
            assert served.headers["content-type"].startswith(CONTENT_TYPES[suffix]), (url, served.headers)
            name = url.rsplit("/", 1)[-1]
            assert served.content == (ASSETS_DIR / name).read_bytes(), f"{url} is not the package's file"


def test_swagger_ui_loads_its_own_script_and_style(open_service):
    html = open_service.get("/docs").text
    assert '<script src="/docs/assets/swagger-ui-bundle.js">' in html
    assert 'href="/docs/assets/swagger-ui.css"' in html
    assert "cdn" not in html.lower()
    assert open_service.get("/redoc").status_code == 404  # off: ReDoc's bundle fetches its logo from a CDN


def test_the_docs_keep_the_api_key_and_openapi_json_works():
    """With a key, /docs, its files and /openapi.json need it like every route but /healthz; the files are
    counted under their mount in /metrics, not as unmatched paths."""
    with running(create_app(ServiceSettings(api_key=KEY))) as http:
        for path in ("/docs", "/openapi.json", "/docs/assets/swagger-ui-bundle.js", "/docs/assets/swagger-ui.css"):
            refused = http.get(path)
            assert refused.status_code == 401 and "API key" in refused.json()["detail"], path
            assert http.get(path, headers={"x-api-key": KEY}).status_code == 200, path
        schema = http.get("/openapi.json", headers={"x-api-key": KEY}).json()
        assert "/v1/shots" in schema["paths"] and not any(p.startswith("/docs") for p in schema["paths"])
        assert http.get("/docs/assets/../app.py", headers={"x-api-key": KEY}).status_code == 404
        metrics = http.get("/metrics", headers={"x-api-key": KEY}).text
        assert 'route="/docs/assets",status="200"' in metrics and 'route="/docs/assets",status="401"' in metrics


def offline_page(page) -> tuple[list[str], list[str]]:
    """Blocks every request whose host is not loopback; returns (blocked URLs, every URL requested)."""
    blocked, requested = [], []
    page.on("request", lambda request: requested.append(request.url))

    def only_loopback(route):
        url = route.request.url
        if urlsplit(url).scheme in ("http", "https", "ws", "wss") and urlsplit(url).hostname not in LOCAL_HOSTS:
            blocked.append(url)
            route.abort()
        else:
            route.continue_()

    page.route("**/*", only_loopback)
    return blocked, requested


def left_loopback(urls: list[str]) -> list[str]:
    return [u for u in urls if urlsplit(u).scheme not in ("data", "blob") and urlsplit(u).hostname not in LOCAL_HOSTS]


@pytest.mark.skipif(browser.missing() is not None, reason=str(browser.missing()))
def test_swagger_ui_renders_in_chromium_with_the_internet_blocked(open_service, tmp_path):
    base = str(open_service.base_url).rstrip("/")
    with browser.headless_page() as page:
        errors: list[str] = []
        page.on("pageerror", lambda error: errors.append(str(error)))
        blocked, requested = offline_page(page)

        page.goto(f"{base}/docs")
        shots = page.locator(".opblock-post .opblock-summary-path[data-path='/v1/shots']")
        shots.wait_for(timeout=15_000)
        assert shots.first.is_visible()
        summary = page.locator(".opblock-post:has(.opblock-summary-path[data-path='/v1/shots'])").first
        assert summary.locator(".opblock-summary-method").inner_text() == "POST"
        assert page.locator(".opblock-post .opblock-summary-path[data-path='/v1/shots/batch']").count() == 1
        assert "golfflight" in page.locator(".info .title").inner_text()
        page.screenshot(path=str(tmp_path / "docs.png"), full_page=False)

        assert not errors, errors
        assert urljoin(base, "/docs/assets/swagger-ui-bundle.js") in requested
        assert urljoin(base, "/openapi.json") in requested
        assert not blocked, f"requests off loopback: {blocked}"
        assert not left_loopback(requested), left_loopback(requested)
