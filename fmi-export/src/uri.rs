//! The resource location of `fmi2Instantiate` is a URI; this turns it into a path.

use std::path::PathBuf;

/// Parses `file:///abs/path`, `file:/abs/path`, `file://host/abs/path` (host `localhost` or
/// any name: the path part is used) and a plain absolute path, decoding `%XX` escapes.
/// Returns `None` for anything else (other schemes, relative paths, bad escapes).
pub fn resource_path(uri: &str) -> Option<PathBuf> {
    let rest = if let Some(r) = uri.strip_prefix("file://") {
        // file://host/path or file:///path (empty host)
        let slash = r.find('/')?;
        &r[slash..]
    } else if let Some(r) = uri.strip_prefix("file:") {
        r
    } else {
        uri
    };
    if !rest.starts_with('/') {
        return None;
    }
    let decoded = percent_decode(rest)?;
    Some(PathBuf::from(decoded))
}

fn percent_decode(s: &str) -> Option<String> {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes.get(i + 1..i + 3)?;
            let hex = std::str::from_utf8(hex).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_forms_importers_send() {
        let p = |s| resource_path(s).map(|p| p.to_string_lossy().into_owned());
        assert_eq!(p("file:///tmp/a%20b/resources").as_deref(), Some("/tmp/a b/resources"));
        assert_eq!(p("file:/tmp/x/resources/").as_deref(), Some("/tmp/x/resources/"));
        assert_eq!(p("file://localhost/tmp/x").as_deref(), Some("/tmp/x"));
        assert_eq!(p("file://server/share/x").as_deref(), Some("/share/x"));
        assert_eq!(p("/tmp/plain").as_deref(), Some("/tmp/plain"));
        assert_eq!(p("http://example.org/x"), None);
        assert_eq!(p("file:///bad%2"), None);
        assert_eq!(p("file:///bad%zz"), None);
        assert_eq!(p("relative/path"), None);
    }
}
