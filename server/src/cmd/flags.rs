//! The command-line flags of the service settings, generated from their one declaration
//! (`config::settings::SERVICE`, each setting's `flag`): `textile serve --cache-mib 64`, and
//! `--data-dir` on every command that reads the configuration. Each flag's help is the
//! setting's own (what it does, range, default, environment variable); its value is checked by
//! its type here and by its range where the configuration is loaded, like every other layer.

use clap::{Arg, ArgMatches, Args, Command, FromArgMatches};
use serde_json::{Map, Value as Json};

use crate::config::settings::{describe, Setting, ValueKind, SERVICE};

/// The settings given as flags: those of every command (`EVERY = true`) or those of
/// `textile serve` only, as `key → value`.
#[derive(Debug, Clone, Default)]
pub struct SettingFlags<const EVERY: bool>(pub Map<String, Json>);

/// The settings that have a flag of this kind.
fn flagged(every: bool) -> impl Iterator<Item = &'static Setting> {
    SERVICE.iter().filter(move |s| s.flag.is_some_and(|f| f.every_command == every))
}

impl<const EVERY: bool> FromArgMatches for SettingFlags<EVERY> {
    fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
        let mut flags = SettingFlags(Map::new());
        flags.update_from_arg_matches(m)?;
        Ok(flags)
    }

    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> Result<(), clap::Error> {
        for s in flagged(EVERY) {
            let value = match s.kind {
                ValueKind::Int { .. } => m.get_one::<u64>(s.key).map(|v| Json::from(*v)),
                _ => m.get_one::<String>(s.key).map(|v| Json::from(v.as_str())),
            };
            if let Some(v) = value {
                self.0.insert(s.key.to_string(), v);
            }
        }
        Ok(())
    }
}

impl<const EVERY: bool> Args for SettingFlags<EVERY> {
    fn augment_args(cmd: Command) -> Command {
        flagged(EVERY).fold(cmd, |cmd, s| {
            let Some(flag) = s.flag else { return cmd };
            let arg = Arg::new(s.key).long(flag.long).value_name(flag.value).help(describe(s));
            cmd.arg(match s.kind {
                ValueKind::Int { .. } => arg.value_parser(clap::value_parser!(u64)),
                _ => arg,
            })
        })
    }

    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}
