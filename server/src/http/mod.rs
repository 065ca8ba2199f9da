//! The HTTP service: routes, middleware (CORS, compression of JSON, panic → 500 JSON, the access
//! log) and the
//! modules behind them: errors as HTTP answers, content headers, request extraction, and the
//! route modules (images, descriptive endpoints, 3D assets, static files, OpenAPI), which import
//! nothing from each other; in front of the router, the hot path of remembered cached tiles
//! ([`hot_tiles`]). Nothing outside this folder names it: the crate root dispatches `textile serve` to [`serve`].

pub mod access;
pub mod admin;
pub mod admin_landscapes;
mod bare_errors;
pub mod content;
pub mod error;
pub mod extract;
pub mod hot_tiles;
pub mod images;
pub mod listen;
pub mod meta;
pub mod models;
pub mod openapi;
pub mod samples;
pub mod static_files;
pub mod tiles3d;

use std::sync::Arc;

use axum::extract::DefaultBodyLimit;
use axum::extract::{MatchedPath, Request, State};
use axum::http::{header, HeaderValue, Method};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::{delete, get, post};
use axum::Router;
use tower_http::catch_panic::CatchPanicLayer;
use tower_http::compression::CompressionLayer;
use tower_http::cors::{AllowOrigin, CorsLayer};

use axum::http::{HeaderMap, HeaderName};

use crate::error::ApiError;
use crate::state::AppState;

/// Refuse oversized requests ([`over_limits`]), then count every routed request by route
/// template and status, and time it.
async fn track(State(st): State<Arc<AppState>>, req: Request, next: Next) -> Response {
    // Oversized requests are refused first, untracked (one layer for both: every layer costs a
    // cached tile its share of instructions).
    if let Some(refused) = over_limits(&req) {
        return refused;
    }
    // The matched route shares its text (no copy per request).
    let matched = req.extensions().get::<MatchedPath>().cloned();
    let route = matched.as_ref().map_or("unmatched", |m| m.as_str());
    let started = std::time::Instant::now();
    let resp = next.run(req).await;
    st.metrics.latency.with_label_values(&[route]).observe(started.elapsed().as_secs_f64());
    st.metrics.requests.with_label_values(&[route, resp.status().as_str()]).inc();
    resp
}

/// Most request headers accepted (hyper itself refuses more than [`listen`] lets it read).
pub const MAX_HEADERS: usize = 100;
/// Most bytes of request headers accepted.
pub const MAX_HEADER_BYTES: usize = 64 << 10;
/// Longest request target (path and query) accepted.
pub const MAX_URI_BYTES: usize = 16 << 10;

/// The contract's JSON error (414, 431) of an oversized request, before any route sees it.
/// What hyper refuses itself — a request line of 64 KiB or more, headers beyond what it reads
/// at all — it answers with a bare status, which [`bare_errors`] rewrites as JSON too.
fn over_limits<B>(req: &axum::http::Request<B>) -> Option<Response> {
    let uri = req.uri().path_and_query().map_or(0, |pq| pq.as_str().len());
    if uri > MAX_URI_BYTES {
        return ApiError::new(
            crate::error::Kind::UriTooLong,
            "uri_too_long",
            format!("the request target is {uri} bytes; at most {MAX_URI_BYTES}"),
        )
        .into_response()
        .into();
    }
    let h = req.headers();
    let bytes: usize = h.iter().map(|(k, v)| k.as_str().len() + v.len() + 4).sum();
    if h.len() > MAX_HEADERS || bytes > MAX_HEADER_BYTES {
        return ApiError::new(
            crate::error::Kind::HeadersTooLarge,
            "headers_too_large",
            format!("{} headers of {bytes} bytes; at most {MAX_HEADERS} headers and {MAX_HEADER_BYTES} bytes", h.len()),
        )
        .into_response()
        .into();
    }
    None
}

/// The CORS settings (`cors_origins`): the router's CORS layer is built from them, and the
/// tiles' hot path ([`hot_tiles`]) adds the same headers that layer adds to a GET's answer.
pub struct Cors {
    /// Every origin is allowed (`*`), else the listed ones.
    any: bool,
    origins: Vec<HeaderValue>,
    vary: HeaderValue,
    expose: HeaderValue,
}

/// The response headers a page's scripts may read.
fn exposed() -> [HeaderName; 6] {
    [
        header::ETAG,
        HeaderName::from_static("x-cache"),
        HeaderName::from_static("x-textile-computed"),
        HeaderName::from_static("x-textile-windows"),
        header::CONTENT_RANGE,
        header::LOCATION,
    ]
}

impl Cors {
    /// The settings of the configured origins.
    pub fn new(origins: &[String]) -> Cors {
        let joined = |names: &[HeaderName], by: &str| {
            let text = names.iter().map(HeaderName::as_str).collect::<Vec<_>>().join(by);
            HeaderValue::from_str(&text).unwrap_or(HeaderValue::from_static(""))
        };
        let varies = [header::ORIGIN, header::ACCESS_CONTROL_REQUEST_METHOD, header::ACCESS_CONTROL_REQUEST_HEADERS];
        Cors {
            any: origins.iter().any(|o| o == "*"),
            origins: origins.iter().filter_map(|o| HeaderValue::from_str(o).ok()).collect(),
            vary: joined(&varies, ", "),
            expose: joined(&exposed(), ","),
        }
    }

    /// The router's CORS layer.
    pub fn layer(&self) -> CorsLayer {
        CorsLayer::new()
            .allow_methods([Method::GET, Method::HEAD, Method::POST, Method::DELETE])
            .allow_headers([header::IF_NONE_MATCH, header::CONTENT_TYPE, header::RANGE, header::AUTHORIZATION])
            .expose_headers(exposed())
            .allow_origin(if self.any { AllowOrigin::any() } else { AllowOrigin::list(self.origins.clone()) })
    }

    /// Add to `answer` the headers the layer adds to the answer of a GET with `request` headers.
    pub fn add(&self, request: &HeaderMap, answer: &mut HeaderMap) {
        answer.append(header::VARY, self.vary.clone());
        let allowed = if self.any {
            Some(HeaderValue::from_static("*"))
        } else {
            request.get(header::ORIGIN).filter(|o| self.origins.contains(o)).cloned()
        };
        if let Some(origin) = allowed {
            answer.insert(header::ACCESS_CONTROL_ALLOW_ORIGIN, origin);
        }
        answer.insert(header::ACCESS_CONTROL_EXPOSE_HEADERS, self.expose.clone());
    }
}

/// A route that reads a request body, with the deadline for a body that stops arriving.
fn reads_body(
    route: axum::routing::MethodRouter<Arc<AppState>>,
    stalled: &tower_http::timeout::RequestBodyTimeoutLayer,
) -> axum::routing::MethodRouter<Arc<AppState>> {
    route.layer(stalled.clone())
}

/// Build the router for a state.
pub fn router(state: Arc<AppState>) -> Router {
    let upload_limit = DefaultBodyLimit::max((state.config.max_upload_mib << 20) as usize);
    // A body that stops arriving gets the headers' deadline too (per frame: a slow but steady
    // upload is fine), answered as 408 by the routes that read one — only those are wrapped: on
    // every route it cost a cached tile about 2 % of its instructions (issue 71).
    let body_deadline = std::time::Duration::from_secs(state.config.header_read_timeout_secs);
    let stalled = tower_http::timeout::RequestBodyTimeoutLayer::new(body_deadline);
    let routes = Router::new()
        .route("/", get(static_files::index))
        .route("/world.html", get(static_files::world))
        .route("/3d.html", get(static_files::three_d))
        .route("/terrain.html", get(static_files::terrain))
        .route("/static/{*path}", get(static_files::static_file))
        .route("/health", get(meta::health))
        .route("/ready", get(meta::ready))
        .route("/catalog", get(meta::catalog))
        .route("/openapi.json", get(openapi::openapi))
        .route("/metrics", get(meta::metrics))
        .route("/textures", reads_body(post(admin::upload).layer(upload_limit), &stalled))
        .route("/textures/{id}", get(meta::texture_meta).delete(admin::delete))
        .route("/admin/textures", reads_body(post(admin::upload).layer(upload_limit), &stalled))
        .route("/admin/textures/{id}", delete(admin::delete))
        .route("/admin/landscapes", reads_body(post(admin_landscapes::upload).layer(upload_limit), &stalled))
        .route("/admin/landscapes/{id}", delete(admin_landscapes::delete))
        .route("/textures/{id}/exemplar.png", get(meta::exemplar))
        .route("/textures/{id}/maps/{name}", get(meta::map_image))
        .route("/tiles/{id}/tilejson.json", get(meta::tilejson))
        .route("/tiles/{id}/{z}/{x}/{y}", get(images::tile))
        .route("/windows/{file}", get(images::window))
        .route("/samples/{id}", reads_body(post(samples::samples), &stalled))
        .route("/gltf/{id}/patch.glb", get(models::gltf_patch))
        .route("/gltf/{id}/{z}/{x}/{y}", get(models::gltf_tile))
        .route("/x3d/{id}/patch.x3d", get(models::x3d_patch))
        .route("/3dtiles/{id}/tileset.json", get(tiles3d::tileset_json))
        .route("/3dtiles/{id}/subtrees/{level}/{x}/{y}", get(tiles3d::subtree_file))
        .route("/3dtiles/{id}/tiles/{level}/{x}/{y}", get(tiles3d::content_tile))
        .route("/x3d/{id}/{z}/{x}/{y}", get(models::x3d_tile));
    // Exported archives, served as static files with range requests (what PMTiles readers use).
    let routes = match state.config.archives_dir.as_str() {
        "" => routes,
        dir => {
            use axum::handler::HandlerWithoutStateExt;
            let missing =
                (|uri: axum::extract::OriginalUri| async move { meta::not_found(uri.0).await }).into_service();
            routes.nest_service("/archives", tower_http::services::ServeDir::new(dir).fallback(missing))
        }
    };
    with_middleware(routes, state)
}

/// The service's fallbacks and middleware around a set of routes: JSON 404/405, request
/// metrics, JSON compression, CORS, panics turned into a 500 JSON error, and the access log.
fn with_middleware(routes: Router<Arc<AppState>>, state: Arc<AppState>) -> Router {
    let cors = Cors::new(&state.config.cors_origins).layer();
    let app = routes
        .fallback(meta::not_found)
        .layer(middleware::from_fn_with_state(state.clone(), track))
        .with_state(state.clone());
    // 405s get their JSON body outside routing: the router adds a route's `Allow` header after
    // every layer of that route has run.
    let app = tower::Layer::layer(&middleware::from_fn(meta::method_not_allowed), app);
    let logged = state.access_log.is_some();
    let router = Router::new()
        .fallback_service(app)
        .layer(CompressionLayer::new())
        .layer(cors)
        .layer(CatchPanicLayer::custom(|_| ApiError::internal("the request handler panicked").into_response()));
    // Outermost, so that it logs every answer as sent; absent when there is no access log.
    if logged {
        router.layer(middleware::from_fn_with_state(state, access::record))
    } else {
        router
    }
}

#[cfg(test)]
mod tests {
    use axum::body::Body;
    use axum::http::{Request, StatusCode};
    use tower::ServiceExt;

    use super::*;

    #[tokio::test]
    async fn a_panicking_handler_becomes_a_500_json_error_and_service_goes_on() {
        let cfg = crate::config::Config::load(None, &Default::default()).unwrap();
        let state = Arc::new(AppState::new(cfg).unwrap());
        let routes = Router::new()
            .route(
                "/boom",
                get(|| async {
                    if std::hint::black_box(true) {
                        panic!("deliberate");
                    }
                    "unreachable"
                }),
            )
            .route("/ok", get(|| async { "ok" }));
        let app = with_middleware(routes, state);
        let r = app.clone().oneshot(Request::get("/boom").body(Body::empty()).unwrap()).await.unwrap();
        assert_eq!(r.status(), StatusCode::INTERNAL_SERVER_ERROR);
        let body = axum::body::to_bytes(r.into_body(), 1 << 16).await.unwrap();
        let v: serde_json::Value = serde_json::from_slice(&body).unwrap();
        assert_eq!(v["error"], "internal");
        let r = app.oneshot(Request::get("/ok").body(Body::empty()).unwrap()).await.unwrap();
        assert_eq!(r.status(), StatusCode::OK);
    }

    #[tokio::test]
    async fn the_hot_paths_cors_headers_are_the_layers() {
        for origins in [vec!["*".to_owned()], vec!["https://a.example".to_owned(), "https://c.example".to_owned()]] {
            let cors = Cors::new(&origins);
            let bare = tower::service_fn(|_: Request<Body>| async {
                Ok::<_, std::convert::Infallible>(Response::new(Body::empty()))
            });
            let layered = tower::Layer::layer(&cors.layer(), bare);
            for origin in [None, Some("https://a.example"), Some("https://b.example")] {
                let mut req = Request::get("/tiles/gravel/7/1/1.png");
                if let Some(o) = origin {
                    req = req.header(header::ORIGIN, o);
                }
                let req = req.body(Body::empty()).unwrap();
                let mut ours = HeaderMap::new();
                cors.add(req.headers(), &mut ours);
                let theirs = layered.clone().oneshot(req).await.unwrap();
                assert_eq!(theirs.headers(), &ours, "{origins:?} {origin:?}");
            }
        }
    }
}
