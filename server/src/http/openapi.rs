//! The OpenAPI 3 document of every route: generated from the handlers' annotations, then the
//! image and 3D routes get the query parameters of every mode from the modes' specs (names,
//! types, ranges, which modes accept them), so a new mode's parameters are documented without
//! touching this file.

use axum::Json;
use textile_core::modes::params::{Kind, ParamSpec, Scope, COMMON};
use utoipa::openapi::path::{Parameter, ParameterBuilder, ParameterIn};
use utoipa::openapi::schema::{ObjectBuilder, Type};
use utoipa::openapi::Required;
use utoipa::{Modify, OpenApi};

/// The OpenAPI 3 document of every route, generated from the handlers' annotations.
#[derive(OpenApi)]
#[openapi(
    info(title = "textile", description = "Infinite, deterministic, example-based texture tiles"),
    modifiers(&AdminAliases, &ModeParameters, &ErrorResponses, &AdminToken),
    paths(
        crate::http::meta::health,
        crate::http::meta::ready,
        crate::http::meta::catalog,
        crate::http::meta::texture_meta,
        crate::http::meta::exemplar,
        crate::http::meta::map_image,
        crate::http::meta::tilejson,
        crate::http::images::tile,
        crate::http::images::window,
        crate::http::samples::samples,
        crate::http::admin::upload,
        crate::http::admin::delete,
        crate::http::admin_landscapes::upload,
        crate::http::admin_landscapes::delete,
        openapi,
        crate::http::meta::metrics,
        crate::http::static_files::index,
        crate::http::static_files::world,
        crate::http::static_files::three_d,
        crate::http::static_files::terrain,
        crate::http::models::gltf_tile,
        crate::http::models::gltf_patch,
        crate::http::models::x3d_tile,
        crate::http::models::x3d_patch,
        crate::http::tiles3d::tileset_json,
        crate::http::tiles3d::subtree_file,
        crate::http::tiles3d::content_tile
    )
)]
pub struct ApiDoc;

/// Routes whose query carries the mode parameters.
const WITH_MODE_PARAMETERS: &[&str] = &[
    "/tiles/{id}/{z}/{x}/{y}.{fmt}",
    "/windows/{id}.{fmt}",
    "/samples/{id}",
    "/tiles/{id}/tilejson.json",
    "/gltf/{id}/{z}/{x}/{y}.{ext}",
    "/gltf/{id}/patch.glb",
    "/x3d/{id}/{z}/{x}/{y}.x3d",
    "/x3d/{id}/patch.x3d",
    "/3dtiles/{id}/tileset.json",
    "/3dtiles/{id}/tiles/{level}/{x}/{y}.glb",
];

/// Adds the common and every mode's request parameters to [`WITH_MODE_PARAMETERS`].
struct ModeParameters;

fn parameter(spec: &ParamSpec, modes: &[&str]) -> Parameter {
    let mut schema = ObjectBuilder::new();
    schema = match spec.kind {
        Kind::Choice(values) => schema.schema_type(Type::String).enum_values(Some(values.iter().copied())),
        Kind::Integer { min, max } | Kind::PowerOfTwo { min, max } => {
            schema.schema_type(Type::Integer).minimum(Some(min as f64)).maximum(Some(max as f64))
        }
        Kind::Unit => schema.schema_type(Type::Number).minimum(Some(0.0)).maximum(Some(1.0)),
        Kind::Levels | Kind::Interval { .. } | Kind::Text { .. } => schema.schema_type(Type::String),
    };
    let applies = if modes.is_empty() { String::new() } else { format!(" (mode={})", modes.join(", mode=")) };
    let shape = match spec.kind {
        Kind::Levels => " One value in [0, 1], or a comma list of one per level, coarse to fine.".to_string(),
        Kind::Interval { min, max } => format!(" LOW,HIGH with {min} <= LOW <= HIGH <= {max}."),
        Kind::PowerOfTwo { .. } => " A power of two.".to_string(),
        // The length is checked by the server (400), not declared: a longer query is a 414 the
        // URL limit answers before any parameter is read.
        Kind::Text { max_len } => format!(" At most {max_len} characters."),
        _ => String::new(),
    };
    ParameterBuilder::new()
        .name(spec.name)
        .parameter_in(ParameterIn::Query)
        .required(Required::False)
        .description(Some(format!("{}{applies}.{shape}", spec.help)))
        .schema(Some(schema.build()))
        .build()
}

impl Modify for ModeParameters {
    fn modify(&self, doc: &mut utoipa::openapi::OpenApi) {
        let mut params: Vec<Parameter> = COMMON.iter().map(|s| parameter(s, &[])).collect();
        let mut seen: Vec<(&str, Vec<&str>, ParamSpec)> = Vec::new();
        for m in textile_core::modes::all() {
            for s in m.specs.iter().filter(|s| s.scope == Scope::Request) {
                match seen.iter_mut().find(|(n, _, _)| *n == s.name) {
                    Some((_, modes, _)) => modes.push(m.name),
                    None => seen.push((s.name, vec![m.name], *s)),
                }
            }
        }
        params.extend(seen.iter().map(|(_, modes, s)| parameter(s, modes)));
        for (path, item) in doc.paths.paths.iter_mut() {
            if !WITH_MODE_PARAMETERS.contains(&path.as_str()) {
                continue;
            }
            for op in [item.get.as_mut(), item.post.as_mut(), item.delete.as_mut()].into_iter().flatten() {
                op.parameters.get_or_insert_with(Vec::new).extend(params.iter().cloned());
            }
        }
    }
}

/// Documents the JSON error answers on every operation: the `ErrorBody` schema
/// (`{"error", "message"}`), and the statuses any route may answer besides its own — 400 (bad
/// path or query), 404 (unknown texture or route), 414 and 431 (oversized requests), 503 (loading,
/// overloaded) — so that contract tests can hold every answer to the document.
struct ErrorResponses;

impl Modify for ErrorResponses {
    fn modify(&self, doc: &mut utoipa::openapi::OpenApi) {
        use utoipa::openapi::{ContentBuilder, Ref, ResponseBuilder};
        let schema = ObjectBuilder::new()
            .property(
                "error",
                ObjectBuilder::new().schema_type(Type::String).description(Some("machine-readable code")),
            )
            .property(
                "message",
                ObjectBuilder::new().schema_type(Type::String).description(Some("what was wrong and what is allowed")),
            )
            .required("error")
            .required("message")
            .build();
        doc.components.get_or_insert_with(Default::default).schemas.insert("ErrorBody".into(), schema.into());
        let generic = [
            ("400", "bad path or parameters"),
            ("404", "unknown texture or route"),
            ("414", "request target too long"),
            ("431", "too many or too large headers"),
            ("503", "loading or overloaded; see Retry-After"),
        ];
        for (_, item) in doc.paths.paths.iter_mut() {
            for op in [item.get.as_mut(), item.post.as_mut(), item.delete.as_mut()].into_iter().flatten() {
                for (code, what) in generic {
                    op.responses
                        .responses
                        .entry(code.into())
                        .or_insert_with(|| ResponseBuilder::new().description(what).build().into());
                }
                for (code, r) in op.responses.responses.iter_mut() {
                    if !code.starts_with('4') && !code.starts_with('5') {
                        continue;
                    }
                    if let utoipa::openapi::RefOr::T(resp) = r {
                        let content = ContentBuilder::new().schema(Some(Ref::from_schema_name("ErrorBody"))).build();
                        resp.content.insert("application/json".into(), content);
                    }
                }
            }
        }
    }
}

/// Adds the upload's fields (query parameters of `POST /admin/textures`) from the settings table,
/// then documents `POST /textures` and `DELETE /textures/{id}`, the API contract's names of the
/// admin routes, as copies of `POST /admin/textures` and `DELETE /admin/textures/{id}` (with
/// operation ids of their own).
struct AdminAliases;

impl Modify for AdminAliases {
    fn modify(&self, doc: &mut utoipa::openapi::OpenApi) {
        let paths = &mut doc.paths.paths;
        // The upload's fields, as the settings table declares them.
        if let Some(op) = paths.get_mut("/admin/textures").and_then(|i| i.post.as_mut()) {
            let fields = crate::config::settings::TEXTURE_FIELDS.iter().map(|s| parameter(s, &[]));
            op.parameters.get_or_insert_with(Vec::new).extend(fields);
        }
        let post = paths.get("/admin/textures").and_then(|i| i.post.clone());
        let delete = paths.get("/admin/textures/{id}").and_then(|i| i.delete.clone());
        if let Some(mut op) = post {
            op.operation_id = Some("upload_alias".into());
            paths.entry("/textures".into()).or_default().post = Some(op);
        }
        if let Some(mut op) = delete {
            op.operation_id = Some("delete_alias".into());
            paths.entry("/textures/{id}".into()).or_default().delete = Some(op);
        }
    }
}

/// Declares the admin API's bearer token (`security(("admin_token" = []))` on its routes).
struct AdminToken;

impl Modify for AdminToken {
    fn modify(&self, doc: &mut utoipa::openapi::OpenApi) {
        use utoipa::openapi::security::{Http, HttpAuthScheme, SecurityScheme};
        let scheme = Http::builder()
            .scheme(HttpAuthScheme::Bearer)
            .description(Some("the configured admin_token (TEXTILE_ADMIN_TOKEN); without one the admin API is off"))
            .build();
        doc.components
            .get_or_insert_with(Default::default)
            .security_schemes
            .insert("admin_token".into(), SecurityScheme::Http(scheme));
    }
}

/// This document.
#[utoipa::path(get, path = "/openapi.json", tag = "service", responses((status = 200, description = "OpenAPI 3")))]
pub async fn openapi() -> Json<utoipa::openapi::OpenApi> {
    Json(ApiDoc::openapi())
}
