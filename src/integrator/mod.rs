//! Integrators: `path` (surfaces only), `volpath`, `volpath_snee` (volpath with subdivision NEE), and the
//! `moment` wrapper that also outputs the per-pixel second moment.

pub mod manifold;
pub mod path;
pub mod snee;
pub mod stats;
pub mod volpath;
pub mod volpathmis;

use crate::scene::desc::{ObjectDesc, PluginKind};
use crate::scene::{Error, Result};
use snee::{SneeOptions, SneeTechnique, SneeTransport};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorKind {
    Path,
    Volpath,
    Volpathmis,
    VolpathSnee,
}

/// Integrator settings (Mitsuba's `MonteCarloIntegrator` parameters).
#[derive(Clone, Debug)]
pub struct IntegratorDesc {
    pub kind: IntegratorKind,
    /// -1 = unbounded.
    pub max_depth: i32,
    pub rr_depth: i32,
    pub hide_emitters: bool,
    /// Wrapped in `moment`: also output the per-pixel second moment.
    pub moment: bool,
    /// `volpath_snee`'s `snee` and `transport` options (defaults elsewhere).
    pub snee: SneeOptions,
    /// `volpath_snee`'s `connection`: the paper's estimator or the complete one (manifold NEE).
    pub connection: manifold::Connection,
}

impl Default for IntegratorDesc {
    fn default() -> Self {
        IntegratorDesc {
            kind: IntegratorKind::Path,
            max_depth: -1,
            rr_depth: 5,
            hide_emitters: false,
            moment: false,
            snee: SneeOptions::default(),
            connection: manifold::Connection::default(),
        }
    }
}

impl IntegratorDesc {
    pub fn from_desc(obj: &ObjectDesc) -> Result<IntegratorDesc> {
        let props = &obj.props;
        if obj.plugin == "moment" {
            let nested = props.objects_of(PluginKind::Integrator);
            props.finish()?;
            let Some((_, first)) = nested.first() else {
                return Err(Error::at(&obj.pos, "moment: expects a nested integrator"));
            };
            if nested.len() > 1 {
                return Err(Error::at(&nested[1].1.pos, "moment: only one nested integrator is supported"));
            }
            let mut inner = IntegratorDesc::from_desc(first)?;
            inner.moment = true;
            return Ok(inner);
        }
        let kind = match obj.plugin.as_str() {
            "path" => IntegratorKind::Path,
            "volpath" => IntegratorKind::Volpath,
            "volpathmis" => IntegratorKind::Volpathmis,
            "volpath_snee" => IntegratorKind::VolpathSnee,
            other => {
                return Err(Error::at(
                    &obj.pos,
                    format!(
                    "integrator \"{}\" is not supported (supported: path, volpath, volpathmis, volpath_snee, moment)",
                    other
                ),
                ))
            }
        };
        let max_depth = props.int("max_depth", -1)?;
        if max_depth < -1 {
            return Err(props.error("max_depth", "max_depth must be -1 (unbounded) or non-negative"));
        }
        let rr_depth = props.int("rr_depth", 5)?;
        if rr_depth <= 0 {
            return Err(props.error("rr_depth", "rr_depth must be positive"));
        }
        let hide_emitters = props.bool("hide_emitters", false)?;
        let mut snee = SneeOptions::default();
        let mut connection = manifold::Connection::default();
        if kind == IntegratorKind::VolpathSnee {
            connection = match props.string("connection", "paper")?.as_str() {
                "paper" => manifold::Connection::Paper,
                "complete" => manifold::Connection::Complete,
                other => {
                    return Err(props.error(
                        "connection",
                        format!("volpath_snee: connection = \"{}\" is not one of paper, complete", other),
                    ))
                }
            };
            snee.technique = match props.string("snee", "mis")?.as_str() {
                "mis" => SneeTechnique::Mis,
                "snee" => SneeTechnique::Snee,
                "forward" => SneeTechnique::Forward,
                other => {
                    return Err(props
                        .error("snee", format!("volpath_snee: snee = \"{}\" is not one of mis, snee, forward", other)))
                }
            };
            snee.rate = props.float_opt("snee_rate")?;
            if let Some(r) = snee.rate {
                if !(0.0..=1.0).contains(&r) {
                    return Err(props.error("snee_rate", "volpath_snee: snee_rate must be in [0, 1]"));
                }
            }
            snee.transport = match props.string("transport", "all")?.as_str() {
                "all" => SneeTransport::All,
                "snee" => SneeTransport::Snee,
                other => {
                    return Err(props.error(
                        "transport",
                        format!("volpath_snee: transport = \"{}\" is not one of all, snee", other),
                    ))
                }
            };
        }
        props.finish()?;
        let clamp = |v: i64| v.clamp(-1, i32::MAX as i64) as i32;
        Ok(IntegratorDesc {
            kind,
            max_depth: clamp(max_depth),
            rr_depth: clamp(rr_depth),
            hide_emitters,
            moment: false,
            snee,
            connection,
        })
    }
}
