//! Scanning numbers out of BVH text: the hot loop of reading. Decimal values
//! with up to 15–16 significant digits (all that exporters write) take
//! Clinger's exact fast path, one multiply or divide by an exact power of
//! ten; anything longer falls back to the standard library's correctly
//! rounded parser, so every value is the nearest f64 either way.

const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20,
    1e21, 1e22,
];

/// Why a token could not be read as a finite number.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum TokenProblem {
    NonNumeric,
    NonFinite,
}

/// A bad token: which value of the line it would have been, and its text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) struct TokenError {
    pub index: usize,
    pub problem: TokenProblem,
    pub token: String,
}

#[inline(always)]
fn is_blank(b: u8) -> bool {
    b == b' ' || b == b'\t' || b == b'\r' || b == b'\x0c' || b == b'\x0b'
}

/// Reads the values of one line starting at `pos`, appending them to `out`.
/// Stops at `\n` or the end of `bytes`; returns the number of values and the
/// index just past the line (past its `\n`). Values may be separated by
/// spaces or tabs, or glued to the next value's sign (`0.0-7.509`).
#[inline]
pub(super) fn scan_line(bytes: &[u8], mut pos: usize, out: &mut Vec<f64>) -> Result<(usize, usize), TokenError> {
    let n = bytes.len();
    let mut count = 0;
    while pos < n {
        let b = bytes[pos];
        if b == b'\n' {
            return Ok((count, pos + 1));
        }
        if is_blank(b) {
            pos += 1;
            continue;
        }
        let start = pos;
        match parse_number(bytes, &mut pos) {
            Some(v) if v.is_finite() => {
                let ends_cleanly = pos == n || {
                    let t = bytes[pos];
                    t == b'\n' || is_blank(t) || t == b'-' || t == b'+'
                };
                if !ends_cleanly {
                    return Err(token_error(bytes, start, count));
                }
                out.push(v);
                count += 1;
            }
            Some(_) => {
                let mut err = token_error(bytes, start, count);
                err.problem = TokenProblem::NonFinite;
                return Err(err);
            }
            None => return Err(token_error(bytes, start, count)),
        }
    }
    Ok((count, n))
}

/// Reads exactly the numbers of a short header field (OFFSET, Frame Time).
pub(super) fn scan_fields(text: &str) -> Result<Vec<f64>, TokenError> {
    let mut out = Vec::with_capacity(3);
    scan_line(text.as_bytes(), 0, &mut out)?;
    Ok(out)
}

fn token_error(bytes: &[u8], start: usize, index: usize) -> TokenError {
    let end = bytes[start..].iter().position(|&b| b == b'\n' || is_blank(b)).map_or(bytes.len(), |p| start + p);
    let raw = &bytes[start..end.min(start + 40)];
    let token = String::from_utf8_lossy(raw).into_owned();
    let word = token.trim_start_matches(['-', '+']).to_ascii_lowercase();
    // NaN, inf, infinity, and MSVC's 1.#IND / 1.#QNAN / 1.#INF spellings.
    let non_finite = word.starts_with("nan") || word.starts_with("inf") || word.contains('#');
    let problem = if non_finite { TokenProblem::NonFinite } else { TokenProblem::NonNumeric };
    TokenError { index, problem, token }
}

/// Parses `[+-] digits [. digits] [(e|E) [+-] digits]` at `*pos`, advancing
/// past it. Returns `None` when no digits are there.
#[inline(always)]
fn parse_number(s: &[u8], pos: &mut usize) -> Option<f64> {
    let n = s.len();
    let start = *pos;
    let mut i = start;
    let negative = match s.get(i) {
        Some(b'-') => {
            i += 1;
            true
        }
        Some(b'+') => {
            i += 1;
            false
        }
        _ => false,
    };
    let mut mantissa: u64 = 0;
    let mut exp10: i64 = 0;
    let mut digits = 0usize;
    // Once the mantissa holds 18 digits, the fast path is off anyway.
    let mut overflow = false;
    while i < n {
        let d = s[i].wrapping_sub(b'0');
        if d > 9 {
            break;
        }
        if mantissa < 100_000_000_000_000_000 {
            mantissa = mantissa * 10 + d as u64;
        } else {
            overflow = true;
        }
        digits += 1;
        i += 1;
    }
    if i < n && s[i] == b'.' {
        i += 1;
        while i < n {
            let d = s[i].wrapping_sub(b'0');
            if d > 9 {
                break;
            }
            if mantissa < 100_000_000_000_000_000 {
                mantissa = mantissa * 10 + d as u64;
                exp10 -= 1;
            } else {
                overflow = true;
            }
            digits += 1;
            i += 1;
        }
    }
    if digits == 0 {
        return None;
    }
    if i < n && (s[i] == b'e' || s[i] == b'E') {
        let mut j = i + 1;
        let exp_negative = match s.get(j) {
            Some(b'-') => {
                j += 1;
                true
            }
            Some(b'+') => {
                j += 1;
                false
            }
            _ => false,
        };
        let exp_start = j;
        let mut e: i64 = 0;
        while j < n && s[j].is_ascii_digit() {
            e = (e * 10 + (s[j] - b'0') as i64).min(100_000);
            j += 1;
        }
        if j == exp_start {
            return None;
        }
        exp10 += if exp_negative { -e } else { e };
        i = j;
    }
    *pos = i;
    if !overflow && mantissa <= 1 << 53 && exp10.abs() <= 22 {
        let m = mantissa as f64;
        let v = if exp10 < 0 { m / POW10[(-exp10) as usize] } else { m * POW10[exp10 as usize] };
        return Some(if negative { -v } else { v });
    }
    // The scanned bytes are ASCII digits, signs, '.', 'e' and 'E'.
    std::str::from_utf8(&s[start..i]).ok()?.parse::<f64>().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn values(line: &str) -> Result<Vec<f64>, TokenError> {
        let mut out = Vec::new();
        scan_line(line.as_bytes(), 0, &mut out)?;
        Ok(out)
    }

    #[test]
    fn reads_plain_leading_dot_exponent_and_signed_values() {
        assert_eq!(
            values("1 -2.5 .0083333 1.5E-7 +3e2 -0.000").unwrap(),
            vec![1.0, -2.5, 0.0083333, 1.5e-7, 300.0, -0.0]
        );
    }

    #[test]
    fn splits_values_glued_to_a_minus_sign() {
        assert_eq!(values("0.0-7.509 1.25-3-4").unwrap(), vec![0.0, -7.509, 1.25, -3.0, -4.0]);
    }

    #[test]
    fn tabs_carriage_returns_and_repeated_spaces_separate_values() {
        assert_eq!(values("\t1\t\t2   3\r").unwrap(), vec![1.0, 2.0, 3.0]);
    }

    #[test]
    fn stops_at_newline_and_reports_where_the_next_line_starts() {
        let mut out = Vec::new();
        let (count, next) = scan_line(b"1 2\n3", 0, &mut out).unwrap();
        assert_eq!((count, next), (2, 4));
    }

    #[test]
    fn every_value_is_the_correctly_rounded_nearest_double() {
        let cases = [
            "0.1",
            "-123.456789",
            "179.99999999999997",
            "9007199254740993",
            "1.7976931348623157e308",
            "4.9e-324",
            "0.30000000000000004",
            "123456789012345678901234567890",
            "2.2250738585072011e-308",
        ];
        for text in cases {
            assert_eq!(values(text).unwrap(), vec![text.parse::<f64>().unwrap()], "{text}");
        }
    }

    #[test]
    fn nan_infinity_and_overflow_are_non_finite_errors_naming_the_value_index() {
        for (line, index) in [("1 nan", 1), ("-inf 2", 0), ("1 2 1.#QNAN", 2), ("1e400", 0), ("NaN", 0)] {
            let err = values(line).unwrap_err();
            assert_eq!((err.index, err.problem), (index, TokenProblem::NonFinite), "{line}");
        }
    }

    #[test]
    fn words_and_half_numbers_are_non_numeric_errors_with_their_token() {
        for (line, token) in [("1 abc", "abc"), ("1.0x 2", "1.0x"), ("1e", "1e"), ("--1", "--1"), (".", ".")] {
            let err = values(line).unwrap_err();
            assert_eq!(err.problem, TokenProblem::NonNumeric, "{line}");
            assert_eq!(err.token, token);
        }
    }
}
