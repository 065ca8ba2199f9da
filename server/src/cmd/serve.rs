//! `textile serve`: load the configuration, start listening at once (answering `/health`, and
//! 503 elsewhere while textures load), decode the exemplars (modes that need only the exemplar
//! serve from then on), load or compute analyses, announce the viewer URL, and drain in-flight
//! requests on SIGINT/SIGTERM for at most `shutdown_grace_secs` (a signal during start-up stops
//! the loading and never announces ready). Connections are accepted by [`listen`]. The access
//! log, if configured, is opened before listening, reopened on SIGHUP and flushed at exit.

use std::sync::Arc;
use std::time::Duration;

use tokio::net::TcpListener;
use tokio::sync::watch;
use tracing::{info, warn};

use crate::cmd::args::{CliResult, ServeArgs};
use crate::config::Config;
use crate::http::listen::{self, Limits};
use crate::state::AppState;
use crate::textures::{analyse_registry, prepare_registry, LoadError, Texture};

/// Run the server until a shutdown signal.
pub fn run(args: ServeArgs) -> CliResult {
    let overrides = args.config.overrides(Some(&args.settings));
    let cfg = Config::load(args.config.config.as_deref(), &overrides)?;
    if args.print_config {
        print!("{}", cfg.to_commented_toml()?);
        return Ok(());
    }
    let filter = tracing_subscriber::EnvFilter::try_from_env("TEXTILE_LOG")
        .or_else(|_| tracing_subscriber::EnvFilter::try_from_default_env())
        .unwrap_or_else(|_| "info".into());
    tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .init();
    rayon::ThreadPoolBuilder::new()
        .num_threads(cfg.worker_threads)
        .thread_name(|i| format!("textile-synth-{i}"))
        .build_global()?;
    let rt = tokio::runtime::Builder::new_multi_thread().enable_all().build()?;
    let result = rt.block_on(serve(cfg));
    // Do not wait for an analysis abandoned by a shutdown during start-up.
    rt.shutdown_timeout(Duration::from_millis(100));
    result
}

async fn serve(cfg: Config) -> CliResult {
    let listener = TcpListener::bind(&cfg.bind).await.map_err(|e| format!("cannot listen on {}: {e}", cfg.bind))?;
    let addr = listener.local_addr()?;
    crate::memory::tune_allocator();
    let limits = Limits {
        max_connections: cfg.max_connections,
        header_read_timeout: Duration::from_secs(cfg.header_read_timeout_secs),
        shutdown_grace: Duration::from_secs(cfg.shutdown_grace_secs),
    };
    // One server per data directory, taken before anything is written there (uploads, analyses).
    // A directory that cannot be written at all is not locked: nothing is stored in it (the
    // registry says so when it loads). Any other failure to lock a directory stops the start.
    let _owner = match crate::textures::lock::DataDirLock::acquire(&cfg.data_dir()) {
        Ok(l) => Some(l),
        Err(e @ crate::textures::lock::LockError::Unwritable { .. }) => {
            warn!("{e}");
            None
        }
        Err(e) => return Err(Box::new(e)),
    };
    let mut state = AppState::new(cfg)?;
    if !state.config.access_log.is_empty() {
        let c = &state.config;
        let format = crate::access_log::Format::parse(&c.access_log_format).unwrap_or(crate::access_log::Format::Json);
        let (written, dropped) = (state.metrics.access_log_lines.clone(), state.metrics.access_log_dropped.clone());
        let log = crate::access_log::AccessLog::open(&c.access_log, format, c.access_log_buffer, written, dropped)
            .map_err(|e| format!("cannot open the access log: {e}"))?;
        state.access_log = Some(log);
    }
    let state = Arc::new(state);
    reopen_on_sighup(state.clone());
    let app = crate::http::router(state.clone());
    info!("listening on http://{addr}/ (loading textures)");
    // One shutdown signal for everything: the accept loop, and the loading below.
    let (stop_tx, stop) = watch::channel(false);
    {
        let state = state.clone();
        tokio::spawn(async move {
            shutdown_signal().await;
            state.stopping.set();
            let _ = stop_tx.send(true);
        });
    }
    // Exemplars first (modes that need only the exemplar serve at once), then the configured
    // textures' analyses on the analysis pool. Uploads are loaded (their stored analyses read,
    // or computed) in the background after them, like new uploads, so they never hold back
    // readiness: `/ready` is the configured textures' (issue 71: 11 stored uploads held it
    // back 5.6 s); `GET /textures/{id}` says `analysing` until an upload is in.
    let loader = {
        let state = state.clone();
        tokio::task::spawn_blocking(move || {
            let log = |s: String| info!("{s}");
            let cfg = crate::uploads::with_stored(&state.config, &log);
            let reg = Arc::new(prepare_registry(&cfg, &log)?);
            state.set_registry(reg.clone());
            let now = |t: &Texture| !t.config.uploaded;
            state.analysis_pool.run(|| analyse_registry(&cfg, &reg, &now, &log, &state.stopping))?;
            state.loaded.store(true, std::sync::atomic::Ordering::Relaxed);
            Ok(())
        })
    };
    let hot = crate::http::hot_tiles::Shared::new(state.clone());
    let service = move |peer| crate::http::hot_tiles::HotTiles::new(hot.clone(), app.clone(), peer);
    let server = tokio::spawn(listen::serve(listener, service, limits, stop.clone()));
    tokio::spawn(crate::memory::return_freed_memory());
    let mut stopping = stop.clone();
    tokio::select! {
        loaded = loader => match loaded? {
            Ok(()) => {
                for tex in state.registry().iter().flat_map(|r| r.list.clone()) {
                    if tex.analysis.get().is_none() && tex.failure.get().is_none() {
                        crate::uploads::analyse_in_background(state.clone(), tex);
                    }
                }
                let reg = state.registry();
                let (n, l) = reg.map(|r| (r.list.len(), r.landscapes.len())).unwrap_or((0, 0));
                let plural = |k: usize| if k == 1 { "" } else { "s" };
                let landscapes = match l {
                    0 => String::new(),
                    l => format!(", {l} landscape{}", plural(l)),
                };
                println!("textile ready: viewer at http://{addr}/ ({n} texture{}{landscapes})", plural(n));
                use std::io::Write;
                let _ = std::io::stdout().flush();
            }
            Err(LoadError::Stopped) => info!("stopped while loading textures"),
            Err(e) => {
                warn!("{e}");
                return Err(Box::new(e));
            }
        },
        // A signal while loading: stop at once (the analysis thread is abandoned at exit).
        _ = stopping.wait_for(|s| *s) => info!("stopped while loading textures"),
    }
    let drained = server.await?;
    if let Some(log) = &state.access_log {
        log.close(Duration::from_secs(2));
    }
    if drained {
        info!("shut down cleanly");
    } else {
        warn!("shut down with requests still open after the drain deadline");
    }
    Ok(())
}

/// SIGHUP: reopen the access log (after logrotate moved it away); without one, nothing.
fn reopen_on_sighup(state: Arc<AppState>) {
    #[cfg(unix)]
    tokio::spawn(async move {
        let Ok(mut hup) = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::hangup()) else { return };
        while hup.recv().await.is_some() {
            match &state.access_log {
                Some(log) => {
                    info!("SIGHUP: reopening the access log");
                    log.reopen();
                }
                None => info!("SIGHUP: no access log to reopen"),
            }
        }
    });
}

async fn shutdown_signal() {
    let ctrl_c = async {
        let _ = tokio::signal::ctrl_c().await;
    };
    #[cfg(unix)]
    let term = async {
        match tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate()) {
            Ok(mut s) => {
                s.recv().await;
            }
            Err(_) => std::future::pending::<()>().await,
        }
    };
    #[cfg(not(unix))]
    let term = std::future::pending::<()>();
    tokio::select! { _ = ctrl_c => {}, _ = term => {} }
    info!("shutdown signal: draining in-flight requests");
}
