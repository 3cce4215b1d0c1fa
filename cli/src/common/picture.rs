//! The arguments of the commands that draw pictures: image sizes and views.

use crate::common::error::{CliError, CliResult};

/// Parses `WxH`.
pub fn parse_size(s: &str) -> CliResult<(u32, u32)> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("size '{s}' must be WIDTHxHEIGHT, e.g. 800x600"))?;
    let p = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|_| format!("size '{s}' must be WIDTHxHEIGHT with whole numbers"))
    };
    let (w, h) = (p(w)?, p(h)?);
    ktree::display::check_size(w, h).map_err(CliError::caused)?;
    Ok((w, h))
}

/// A named view or a direction `X,Y,Z`, from the object towards the eye ([`ktree::display::View`]).
pub fn parse_view(s: &str) -> CliResult<[f64; 3]> {
    s.parse::<ktree::display::View>()
        .map(|v| v.toward_eye())
        .map_err(CliError::caused)
}
