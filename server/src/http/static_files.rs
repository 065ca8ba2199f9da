//! The web viewer's files, compiled into the binary (`web/`): pages at `/`, `/world.html`,
//! `/3d.html` and `/terrain.html`,
//! the archive page `/static/pmtiles.html`, scripts, styles and the vendored libraries (with their licences) under `/static/`.

use axum::extract::Path;
use axum::http::{header, HeaderValue};
use axum::response::{IntoResponse, Response};

use crate::error::ApiError;

/// `(path under /static/, content type, bytes)`.
const FILES: &[(&str, &str, &[u8])] = &[
    ("app.js", "text/javascript; charset=utf-8", include_bytes!("../../../web/app.js")),
    ("controls.js", "text/javascript; charset=utf-8", include_bytes!("../../../web/controls.js")),
    ("modes.js", "text/javascript; charset=utf-8", include_bytes!("../../../web/modes.js")),
    ("world.js", "text/javascript; charset=utf-8", include_bytes!("../../../web/world.js")),
    ("terrain.js", "text/javascript; charset=utf-8", include_bytes!("../../../web/terrain.js")),
    ("vendor/maplibre-gl.js", "text/javascript; charset=utf-8", include_bytes!("../../../web/vendor/maplibre-gl.js")),
    ("vendor/maplibre-gl.css", "text/css; charset=utf-8", include_bytes!("../../../web/vendor/maplibre-gl.css")),
    (
        "vendor/LICENSE-maplibre-gl",
        "text/plain; charset=utf-8",
        include_bytes!("../../../web/vendor/LICENSE-maplibre-gl"),
    ),
    ("pmtiles.html", "text/html; charset=utf-8", include_bytes!("../../../web/pmtiles.html")),
    ("pmtiles.js", "text/javascript; charset=utf-8", include_bytes!("../../../web/pmtiles.js")),
    ("vendor/pmtiles.js", "text/javascript; charset=utf-8", include_bytes!("../../../web/vendor/pmtiles.js")),
    ("vendor/LICENSE-pmtiles", "text/plain; charset=utf-8", include_bytes!("../../../web/vendor/LICENSE-pmtiles")),
    ("style.css", "text/css; charset=utf-8", include_bytes!("../../../web/style.css")),
    ("vendor/leaflet.js", "text/javascript; charset=utf-8", include_bytes!("../../../web/vendor/leaflet.js")),
    ("vendor/leaflet.css", "text/css; charset=utf-8", include_bytes!("../../../web/vendor/leaflet.css")),
    ("vendor/ol.js", "text/javascript; charset=utf-8", include_bytes!("../../../web/vendor/ol.js")),
    ("vendor/ol.css", "text/css; charset=utf-8", include_bytes!("../../../web/vendor/ol.css")),
    ("vendor/LICENSE-leaflet", "text/plain; charset=utf-8", include_bytes!("../../../web/vendor/LICENSE-leaflet")),
    ("vendor/LICENSE-ol.md", "text/plain; charset=utf-8", include_bytes!("../../../web/vendor/LICENSE-ol.md")),
    ("vendor/VERSIONS", "text/plain; charset=utf-8", include_bytes!("../../../web/vendor/VERSIONS")),
    ("3d.js", "text/javascript; charset=utf-8", include_bytes!("../../../web/3d.js")),
    (
        "vendor/three/three.module.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/vendor/three/three.module.js"),
    ),
    (
        "vendor/three/three.core.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/vendor/three/three.core.js"),
    ),
    (
        "vendor/three/addons/loaders/GLTFLoader.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/vendor/three/addons/loaders/GLTFLoader.js"),
    ),
    (
        "vendor/three/addons/utils/BufferGeometryUtils.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/vendor/three/addons/utils/BufferGeometryUtils.js"),
    ),
    (
        "vendor/three/addons/utils/SkeletonUtils.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/vendor/three/addons/utils/SkeletonUtils.js"),
    ),
    (
        "vendor/three/addons/controls/MapControls.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/vendor/three/addons/controls/MapControls.js"),
    ),
    (
        "vendor/three/addons/controls/OrbitControls.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/vendor/three/addons/controls/OrbitControls.js"),
    ),
    (
        "vendor/3d-tiles-renderer/index.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/vendor/3d-tiles-renderer/index.js"),
    ),
    (
        "vendor/3d-tiles-renderer/index.core-plugins.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/vendor/3d-tiles-renderer/index.core-plugins.js"),
    ),
    (
        "vendor/3d-tiles-renderer/plugins-RoDI5SD7.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/vendor/3d-tiles-renderer/plugins-RoDI5SD7.js"),
    ),
    (
        "vendor/3d-tiles-renderer/renderer-CUfHAmYW.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/vendor/3d-tiles-renderer/renderer-CUfHAmYW.js"),
    ),
    (
        "vendor/3d-tiles-renderer/renderer-_7gAivIK.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/vendor/3d-tiles-renderer/renderer-_7gAivIK.js"),
    ),
    ("vendor/LICENSE-three", "text/plain; charset=utf-8", include_bytes!("../../../web/vendor/LICENSE-three")),
    (
        "vendor/LICENSE-3d-tiles-renderer",
        "text/plain; charset=utf-8",
        include_bytes!("../../../web/vendor/LICENSE-3d-tiles-renderer"),
    ),
];

fn file(bytes: &'static [u8], content_type: &'static str) -> Response {
    let mut r = bytes.into_response();
    r.headers_mut().insert(header::CONTENT_TYPE, HeaderValue::from_static(content_type));
    r.headers_mut().insert(header::CACHE_CONTROL, HeaderValue::from_static("public, max-age=300"));
    r
}

/// A file under `/static/`.
pub async fn static_file(Path(path): Path<String>) -> Result<Response, ApiError> {
    FILES
        .iter()
        .find(|(p, _, _)| *p == path)
        .map(|(_, ct, b)| file(b, ct))
        .ok_or_else(|| ApiError::not_found_route(&format!("/static/{path}")))
}

/// The infinite-plane viewer.
#[utoipa::path(get, path = "/", tag = "viewer", responses((status = 200, description = "HTML")))]
pub async fn index() -> Response {
    file(include_bytes!("../../../web/index.html"), "text/html; charset=utf-8")
}

/// The Web-Mercator world map (`world=` periodic mode).
#[utoipa::path(get, path = "/world.html", tag = "viewer", responses((status = 200, description = "HTML")))]
pub async fn world() -> Response {
    file(include_bytes!("../../../web/world.html"), "text/html; charset=utf-8")
}

/// The terrain page: the texture over its own heights in MapLibre GL JS.
#[utoipa::path(get, path = "/terrain.html", tag = "viewer", responses((status = 200, description = "HTML")))]
pub async fn terrain() -> Response {
    file(include_bytes!("../../../web/terrain.html"), "text/html; charset=utf-8")
}

/// The 3D viewer: the texture's 3D Tiles tileset in three.js with 3DTilesRendererJS.
#[utoipa::path(get, path = "/3d.html", tag = "viewer", responses((status = 200, description = "HTML")))]
pub async fn three_d() -> Response {
    file(include_bytes!("../../../web/3d.html"), "text/html; charset=utf-8")
}
