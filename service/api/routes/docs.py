"""GET /docs (Swagger UI) rendered offline: its JavaScript, CSS and favicon come from the installed `fastapi-offline`
package (Swagger UI 5, the bundle FastAPI itself would load from a CDN), mounted at /docs/assets, not from the
internet (simulator bays are often offline).

FastAPI's documented way to self-host the docs' assets: the app is made with `docs_url=None` and this route renders
`fastapi.openapi.docs.get_swagger_ui_html` pointing at the local files. ReDoc (/redoc) is off: its bundle fetches its
logo from the vendor's CDN whatever serves the script. Like every route but /healthz and the viewer's page, /docs
and its files need the API key when one is set (`service.api.guards`).
"""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path

from fastapi import APIRouter, FastAPI, Request
from fastapi.openapi.docs import get_swagger_ui_html
from fastapi.responses import HTMLResponse
from fastapi.staticfiles import StaticFiles

DOCS_PATH = "/docs"
ASSETS_PATH = "/docs/assets"

ASSETS_DIR = Path(str(files("fastapi_offline") / "static"))
"""The package's static folder: swagger-ui-bundle.js, swagger-ui.css and favicon.png (and ReDoc's script, unused)."""

router = APIRouter(include_in_schema=False)


@router.get(DOCS_PATH)
async def swagger_ui(request: Request) -> HTMLResponse:
    root, app = request.scope.get("root_path", ""), request.app
    return get_swagger_ui_html(
        openapi_url=root + app.openapi_url,
        title=f"{app.title} - Swagger UI",
        swagger_js_url=f"{root}{ASSETS_PATH}/swagger-ui-bundle.js",
        swagger_css_url=f"{root}{ASSETS_PATH}/swagger-ui.css",
        swagger_favicon_url=f"{root}{ASSETS_PATH}/favicon.png",
        swagger_ui_parameters=app.swagger_ui_parameters,
    )


def mount_assets(app: FastAPI) -> None:
    """The page's files on `app` (which includes `router` and was made with docs_url=None)."""
    app.mount(ASSETS_PATH, StaticFiles(directory=ASSETS_DIR), name="docs-assets")
