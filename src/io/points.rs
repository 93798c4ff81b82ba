//! Reader for plain point files: one `x y z` per line.
//!
//! Format: each non-blank line holds exactly three numbers separated by spaces or tabs.
//! Anything from a `#` to the end of its line is a comment; blank (or comment-only) lines are
//! skipped. Windows line ends are accepted. Numbers are parsed by Rust's `f64` parser (correctly
//! rounded, so a file written with `{}` formatting round-trips exactly); NaN and infinities are
//! rejected.
//!
//! The file is streamed through one reused line buffer, so reading 4·10^6 points allocates
//! nothing per line and never holds the whole text in memory (the peak RSS a benchmark reports
//! then reflects the triangulation, not the file).

use super::IoError;
use glam::DVec3;
use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

/// Reads every point of a text point file (see the module docs for the format).
///
/// Errors name the file and, for a bad line, its 1-based number and what is wrong with it.
pub fn read_points(path: impl AsRef<Path>) -> Result<Vec<DVec3>, IoError> {
    let path = path.as_ref();
    let name = path.display().to_string();
    let file = File::open(path).map_err(|e| IoError {
        path: name.clone(),
        line: None,
        message: format!("cannot open: {e}"),
    })?;
    // Reserve from the file size (a line of three numbers is rarely shorter than ~20 bytes)
    // so that big files do not pay for repeated growth and the doubling slack.
    let size_hint = file
        .metadata()
        .map(|m| (m.len() / 24) as usize)
        .unwrap_or(0);
    let mut points = Vec::with_capacity(size_hint.min(1 << 26));
    parse_points(BufReader::with_capacity(1 << 16, file), &name, &mut points)?;
    points.shrink_to_fit();
    Ok(points)
}

/// Parses points from any reader into `out`; `name` is used in error messages.
pub fn parse_points<R: Read>(
    mut reader: BufReader<R>,
    name: &str,
    out: &mut Vec<DVec3>,
) -> Result<(), IoError> {
    let mut buf: Vec<u8> = Vec::with_capacity(256);
    let mut line_no = 0usize;
    loop {
        buf.clear();
        let n = reader.read_until(b'\n', &mut buf).map_err(|e| IoError {
            path: name.to_string(),
            line: Some(line_no + 1),
            message: format!("read error: {e}"),
        })?;
        if n == 0 {
            return Ok(());
        }
        line_no += 1;
        let err = |message: String| IoError {
            path: name.to_string(),
            line: Some(line_no),
            message,
        };
        let line = std::str::from_utf8(&buf).map_err(|_| err("line is not valid UTF-8".into()))?;
        let content = match line.find('#') {
            Some(i) => &line[..i],
            None => line,
        };
        if let Some(p) = parse_line(content).map_err(err)? {
            out.push(p);
        }
    }
}

/// Parses one comment-stripped line: `Ok(None)` for a blank line.
fn parse_line(content: &str) -> Result<Option<DVec3>, String> {
    let mut tokens = content.split_ascii_whitespace();
    let Some(first) = tokens.next() else {
        return Ok(None);
    };
    let mut xyz = [0.0f64; 3];
    let mut count = 0usize;
    for tok in std::iter::once(first).chain(tokens) {
        if count < 3 {
            xyz[count] = parse_coord(tok, count)?;
        }
        count += 1;
    }
    if count != 3 {
        return Err(format!(
            "expected 3 numbers (x y z), found {count} field{}",
            if count == 1 { "" } else { "s" }
        ));
    }
    Ok(Some(DVec3::from_array(xyz)))
}

fn parse_coord(tok: &str, axis: usize) -> Result<f64, String> {
    let name = ["x", "y", "z"][axis];
    let v: f64 = tok
        .parse()
        .map_err(|_| format!("{name} coordinate `{tok}` is not a number"))?;
    if !v.is_finite() {
        return Err(format!("{name} coordinate `{tok}` is not finite"));
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Vec<DVec3>, IoError> {
        let mut out = Vec::new();
        parse_points(BufReader::new(text.as_bytes()), "test.xyz", &mut out)?;
        Ok(out)
    }

    #[test]
    fn reads_points_comments_and_blank_lines() {
        let text = "# header\n\n0 0 0\n1.5\t-2e3  3 # trailing comment\r\n   \n  # indented comment\n.25 +1 -0\n";
        let pts = parse(text).unwrap();
        assert_eq!(
            pts,
            vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.5, -2000.0, 3.0),
                DVec3::new(0.25, 1.0, -0.0),
            ]
        );
    }

    #[test]
    fn last_line_without_newline_and_empty_input() {
        assert_eq!(parse("1 2 3").unwrap(), vec![DVec3::new(1.0, 2.0, 3.0)]);
        assert!(parse("").unwrap().is_empty());
        assert!(parse("# only a comment\n\n").unwrap().is_empty());
    }

    #[test]
    fn round_trips_display_formatting() {
        let vals = [
            0.1f64,
            1.0 / 3.0,
            6.02214076e23,
            -1e-300,
            std::f64::consts::FRAC_PI_4,
        ];
        let text: String = vals.iter().map(|v| format!("{v} {v} {v}\n")).collect();
        let pts = parse(&text).unwrap();
        for (p, v) in pts.iter().zip(vals) {
            assert_eq!(p.x.to_bits(), v.to_bits());
        }
    }

    #[test]
    fn too_few_numbers_gives_line_and_count() {
        let e = parse("0 0 0\n\n1 2\n").unwrap_err();
        assert_eq!(e.line, Some(3));
        assert_eq!(e.path, "test.xyz");
        assert!(e.message.contains("expected 3 numbers"), "{}", e.message);
        assert!(e.message.contains("found 2"), "{}", e.message);
        assert_eq!(
            e.to_string(),
            "test.xyz:3: expected 3 numbers (x y z), found 2 fields"
        );
    }

    #[test]
    fn too_many_numbers_gives_line_and_count() {
        let e = parse("# c\n1 2 3 4\n").unwrap_err();
        assert_eq!(e.line, Some(2));
        assert!(e.message.contains("found 4"), "{}", e.message);
    }

    #[test]
    fn not_a_number_names_the_token() {
        let e = parse("1 2 3\n1 abc 3\n").unwrap_err();
        assert_eq!(e.line, Some(2));
        assert!(
            e.message.contains("y coordinate `abc` is not a number"),
            "{}",
            e.message
        );
        // A comma-separated line is a "not a number" error, not a silent misread.
        let e = parse("1,2,3\n").unwrap_err();
        assert_eq!(e.line, Some(1));
        assert!(e.message.contains("not a number"), "{}", e.message);
    }

    #[test]
    fn non_finite_is_rejected() {
        for (text, tok) in [
            ("nan 0 0\n", "nan"),
            ("0 inf 0\n", "inf"),
            ("0 0 -1e400\n", "-1e400"),
        ] {
            let e = parse(text).unwrap_err();
            assert_eq!(e.line, Some(1));
            assert!(e.message.contains("is not finite"), "{}", e.message);
            assert!(e.message.contains(tok), "{}", e.message);
        }
    }

    #[test]
    fn invalid_utf8_is_an_error_not_a_panic() {
        let mut out = Vec::new();
        let bytes: &[u8] = b"1 2 3\n\xff\xfe 0 0\n";
        let e = parse_points(BufReader::new(bytes), "bin", &mut out).unwrap_err();
        assert_eq!(e.line, Some(2));
        assert!(e.message.contains("UTF-8"));
    }

    #[test]
    fn missing_file_is_an_error() {
        let e = read_points("/nonexistent/dir/points.xyz").unwrap_err();
        assert_eq!(e.line, None);
        assert!(e.message.starts_with("cannot open"), "{}", e.message);
    }

    #[test]
    fn reads_a_real_file() {
        let dir = std::env::temp_dir().join(format!("slivermesh-points-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("p.xyz");
        let text: String = (0..1000)
            .map(|i| format!("{i} {} {}\n", i * 2, -i))
            .collect();
        std::fs::write(&path, text).unwrap();
        let pts = read_points(&path).unwrap();
        std::fs::remove_dir_all(&dir).ok();
        assert_eq!(pts.len(), 1000);
        assert_eq!(pts[999], DVec3::new(999.0, 1998.0, -999.0));
    }
}
