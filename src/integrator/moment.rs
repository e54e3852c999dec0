//! Mitsuba's `moment`: wraps one integrator and also outputs the per-pixel second moment of its
//! samples (channels `m2.R`, `m2.G`, `m2.B`), from which a variance image follows.
//!
//! | Parameter | Type       | Description                               |
//! |-----------|------------|-------------------------------------------|
//! | (nested)  | integrator | exactly one integrator, rendered as usual |
//!
//! ```xml
//! <integrator type="moment">
//!     <integrator type="volpath"/>
//! </integrator>
//! ```

use super::desc::IntegratorDesc;
use crate::scene::desc::{ObjectDesc, PluginKind};
use crate::scene::{Error, Result};

/// The nested integrator's settings, with `moment` set.
pub fn parse(obj: &ObjectDesc) -> Result<IntegratorDesc> {
    let props = &obj.props;
    let nested = props.objects_of(PluginKind::Integrator);
    props.finish()?;
    let Some((_, first)) = nested.first() else {
        return Err(Error::at(&obj.pos, "moment: expects a nested integrator"));
    };
    if nested.len() > 1 {
        return Err(Error::at(&nested[1].1.pos, "moment: only one nested integrator is supported"));
    }
    let mut inner = super::parse(first)?;
    inner.moment = true;
    Ok(inner)
}
