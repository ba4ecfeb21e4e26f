//! Numbers on the command line: the parsers of the numeric options, and [`show`] (the
//! library's `error::show_number`), which writes a number in a message as a person reads it.
//!
//! A numeric option may be given a negative number, or a list that starts with one
//! (`--step -1`, `--view -30,20,1`): each such option is declared with clap's
//! `allow_hyphen_values`, so that the value reaches its parser here and is refused, or taken,
//! with a message in the option's own terms, instead of clap reading it as an unknown flag.
//! Each parser's message quotes the text as the user wrote it.

pub use cylvol::error::show_number as show;

/// `s` read as a number (`inf` and `nan` included, surrounding blanks ignored).
fn number(s: &str) -> Option<f64> {
    s.trim().parse().ok()
}

/// Parses a length that must be positive and finite; `what` names it in the error
/// (`"step"`).
pub fn positive_finite(s: &str, what: &str) -> Result<f64, String> {
    match number(s) {
        Some(v) if v > 0.0 && v.is_finite() => Ok(v),
        Some(_) => Err(format!("{what} '{s}' must be positive and finite")),
        None => Err(format!("{what} '{s}' is not a number")),
    }
}

/// Parses a whole number in `min..=max` (no upper bound for `u64::MAX`); `what` names it in
/// the error (`"refinement"`).
pub fn whole_in(s: &str, what: &str, min: u64, max: u64) -> Result<u64, String> {
    let t = s.trim();
    match t.parse::<u64>() {
        Ok(n) if (min..=max).contains(&n) => Ok(n),
        _ if t.parse::<i128>().is_ok() => Err(if max == u64::MAX {
            format!("{what} '{s}' must be a whole number, {min} or more")
        } else {
            format!("{what} '{s}' must be a whole number from {min} to {max}")
        }),
        _ => Err(format!("{what} '{s}' is not a whole number")),
    }
}

/// Parses `--step S` (world units), positive and finite.
pub fn parse_step(s: &str) -> Result<f64, String> {
    positive_finite(s, "step")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positive_lengths_and_whole_numbers_say_what_is_wrong() {
        assert_eq!(parse_step(" 0.5 "), Ok(0.5));
        for bad in ["-1", "0", "-0", "inf", "nan", "-inf"] {
            assert_eq!(
                parse_step(bad),
                Err(format!("step '{bad}' must be positive and finite"))
            );
        }
        assert_eq!(
            parse_step("--shade"),
            Err("step '--shade' is not a number".into())
        );
        assert_eq!(whole_in("3", "refinement", 1, 16), Ok(3));
        for bad in ["-1", "0", "17", "99999999999999999999999"] {
            assert_eq!(
                whole_in(bad, "refinement", 1, 16),
                Err(format!(
                    "refinement '{bad}' must be a whole number from 1 to 16"
                ))
            );
        }
        assert_eq!(
            whole_in("-3", "lookups", 0, u64::MAX),
            Err("lookups '-3' must be a whole number, 0 or more".into())
        );
        assert_eq!(
            whole_in("2.5", "refinement", 1, 16),
            Err("refinement '2.5' is not a whole number".into())
        );
    }
}
