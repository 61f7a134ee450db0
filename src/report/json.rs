//! The report as JSON text: figures rounded to drop float noise, deterministically.

use serde::Serialize;

/// Significant digits kept in reported JSON figures: float noise from the arithmetic
/// (7.000000000000007) goes, every measured or planned figure keeps more digits than it is
/// accurate to (micrometres on a metre-sized object, 1e-10 on a unit quaternion).
pub const JSON_SIGNIFICANT_DIGITS: usize = 12;

/// Magnitudes below this are float noise around zero in the report's units (mm, deg, kg, s,
/// a unit quaternion's components): reported as 0.
pub const JSON_ZERO_BELOW: f64 = 1e-10;

/// `value` as JSON text with every fractional number rounded to [`JSON_SIGNIFICANT_DIGITS`]
/// significant digits, magnitudes below [`JSON_ZERO_BELOW`] and -0 written as 0, and integers
/// and field order left as they are. Deterministic: the same value gives the same text.
///
/// # Errors
/// When `value` cannot be serialized (never for the report types).
pub fn to_rounded_json<T: Serialize>(value: &T) -> serde_json::Result<String> {
    Ok(round_json_numbers(&serde_json::to_string(value)?))
}

/// [`to_rounded_json`] on JSON text, pretty-printed with indentation.
///
/// # Errors
/// As [`to_rounded_json`].
pub fn to_rounded_json_pretty<T: Serialize>(value: &T) -> serde_json::Result<String> {
    Ok(round_json_numbers(&serde_json::to_string_pretty(value)?))
}

/// Rewrites every number with a fraction or an exponent in JSON text, outside strings.
fn round_json_numbers(json: &str) -> String {
    let mut out = String::with_capacity(json.len());
    let mut chars = json.char_indices().peekable();
    let mut in_string = false;
    let mut escaped = false;
    while let Some((i, c)) = chars.next() {
        if in_string {
            out.push(c);
            match (escaped, c) {
                (true, _) => escaped = false,
                (false, '\\') => escaped = true,
                (false, '"') => in_string = false,
                _ => {}
            }
            continue;
        }
        if c == '"' {
            in_string = true;
            out.push(c);
            continue;
        }
        if c == '-' || c.is_ascii_digit() {
            let mut end = i + c.len_utf8();
            while let Some(&(j, d)) = chars.peek() {
                if d.is_ascii_digit() || matches!(d, '.' | 'e' | 'E' | '+' | '-') {
                    end = j + d.len_utf8();
                    chars.next();
                } else {
                    break;
                }
            }
            let token = &json[i..end];
            let is_float = token.contains(['.', 'e', 'E']);
            match token.parse::<f64>() {
                Ok(x) if is_float => {
                    let r = round_significant(x, JSON_SIGNIFICANT_DIGITS);
                    let r = if r.abs() < JSON_ZERO_BELOW { 0.0 } else { r };
                    match serde_json::Number::from_f64(r) {
                        Some(n) => out.push_str(&n.to_string()),
                        None => out.push_str(token),
                    }
                }
                _ => out.push_str(token),
            }
            continue;
        }
        out.push(c);
    }
    out
}

/// `x` rounded to `digits` significant digits (through its decimal text, so 7.000000000000007
/// becomes exactly 7.0), with -0 as 0; non-finite values unchanged.
pub fn round_significant(x: f64, digits: usize) -> f64 {
    if !x.is_finite() || x == 0.0 {
        return if x == 0.0 { 0.0 } else { x };
    }
    let r: f64 = format!("{:.*e}", digits.saturating_sub(1), x)
        .parse()
        .unwrap_or(x);
    r + 0.0
}

#[cfg(test)]
mod tests {
    #[test]
    fn reported_figures_lose_float_noise_only() {
        use super::{round_significant, to_rounded_json};
        assert_eq!(round_significant(7.000000000000007, 12), 7.0);
        assert_eq!(round_significant(0.30000000000000004, 12), 0.3);
        assert_eq!(round_significant(-6.225829064425771, 12), -6.22582906443);
        assert_eq!(round_significant(6842.683214567891, 12), 6842.68321457);
        assert_eq!(round_significant(-0.0, 12), 0.0);
        assert!(round_significant(-0.0, 12).is_sign_positive());
        assert_eq!(round_significant(1.5e-18, 12), 1.5e-18);
        #[derive(serde::Serialize)]
        struct T {
            z: Vec<f64>,
            a: f64,
            s: &'static str,
            n: i64,
        }
        let v = to_rounded_json(&T {
            z: vec![7.000000000000007, 3.0, 3.6063889953e-16, -0.0],
            a: -1.25e-3,
            s: "x 7.000000000000007 \" 1.0000000000001",
            n: -12,
        })
        .unwrap();
        assert_eq!(
            v,
            r#"{"z":[7.0,3.0,0.0,0.0],"a":-0.00125,"s":"x 7.000000000000007 \" 1.0000000000001","n":-12}"#
        );
    }
}
