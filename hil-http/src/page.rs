//! Serving a page's files: the style sheet and the single-switch scanning
//! script the query page and the study pages share, compiled-in text
//! assets, and item pictures from a folder.

use std::path::Path;

use crate::Response;

/// The shared style sheet (large type, high contrast, big targets, the
/// switch-scanning highlight), served as `app.css` by the web query page
/// and the study pages; each may add its own sheet after it.
pub const PAGE_CSS: &str = include_str!("../assets/page.css");

/// Single-switch scanning (`window.hilScan`), served as `scan.js` before
/// each page's own script: the query page and the study's participant
/// page step through their controls with it.
pub const SCAN_JS: &str = include_str!("../assets/scan.js");

/// The switch-scanning settings ([`SCAN_JS`] reads them): an on/off box
/// and the step interval, for a page's header.
const SCAN_SETTINGS_HTML: &str = include_str!("../assets/scan-settings.html");

/// The top every page shares, from `<!DOCTYPE html>` to the end of its
/// header: the head (charset, viewport, no referrer, [`PAGE_CSS`] then the
/// page's sheets, [`SCAN_JS`] then its scripts), a skip link, the heading
/// and the switch-scanning settings.
const PAGE_TOP_HTML: &str = include_str!("../assets/page-top.html");

/// The page's own values in its first line:
/// `<!-- page title="…" heading="…" skip="…" skip_label="…" styles="…" scripts="…" -->`.
const PAGE_FIELDS: [&str; 6] = [
    "title",
    "heading",
    "skip",
    "skip_label",
    "styles",
    "scripts",
];

/// A page's HTML with the shared top (`assets/page-top.html`) in place of its
/// first line, which names the page's title, heading, skip-link target and
/// label, and its own style sheets and scripts (space-separated, after
/// `app.css` and `scan.js`). So every page has the same head, header and
/// switch-scanning settings. A page without that line is returned as it is.
///
/// ```
/// let page = hil_http::page::assemble(
///     "<!-- page title=\"T\" heading=\"H\" skip=\"main\" skip_label=\"Skip\" styles=\"a.css\" scripts=\"a.js\" -->\n<main id=\"main\"></main>\n",
/// );
/// assert!(page.starts_with("<!DOCTYPE html>"));
/// assert!(page.contains("<title>T</title>") && page.contains(r#"<h1 id="title">H</h1>"#));
/// assert!(page.contains(r#"<link rel="stylesheet" href="a.css">"#));
/// assert!(page.contains(r#"<script src="a.js" defer></script>"#));
/// assert!(page.contains(r#"id="scan-toggle""#) && page.ends_with("<main id=\"main\"></main>\n"));
/// ```
pub fn assemble(html: &str) -> String {
    let (first, rest) = html.split_once('\n').unwrap_or((html, ""));
    let Some(fields) = first
        .trim()
        .strip_prefix("<!-- page ")
        .and_then(|f| f.strip_suffix("-->"))
        .and_then(page_fields)
    else {
        return html.to_string();
    };
    let tags = |list: &str, tag: fn(&str) -> String| -> String {
        list.split_whitespace().map(tag).collect()
    };
    let styles = tags(&fields[4], |s| {
        format!("<link rel=\"stylesheet\" href=\"{s}\">\n")
    });
    let scripts = tags(&fields[5], |s| {
        format!("<script src=\"{s}\" defer></script>\n")
    });
    let top = PAGE_TOP_HTML
        .replace("{title}", &fields[0])
        .replace("{heading}", &fields[1])
        .replace("{skip}", &fields[2])
        .replace("{skip_label}", &fields[3])
        .replace("{styles}", &styles)
        .replace("{scripts}", &scripts)
        .replace("{scan_settings}", SCAN_SETTINGS_HTML);
    top + rest
}

/// The [`PAGE_FIELDS`] of `key="value" …`, in that order; `None` unless
/// each is given once and nothing else is.
fn page_fields(text: &str) -> Option<Vec<String>> {
    let mut found: Vec<Option<String>> = vec![None; PAGE_FIELDS.len()];
    let mut rest = text.trim();
    while !rest.is_empty() {
        let (key, after) = rest.split_once("=\"")?;
        let (value, after) = after.split_once('"')?;
        let i = PAGE_FIELDS.iter().position(|k| *k == key.trim())?;
        if found[i].replace(value.to_string()).is_some() {
            return None;
        }
        rest = after.trim_start();
    }
    found.into_iter().collect()
}

/// Content type of an HTML page.
pub const HTML: &str = "text/html; charset=utf-8";
/// Content type of a script.
pub const JS: &str = "text/javascript; charset=utf-8";
/// Content type of a style sheet.
pub const CSS: &str = "text/css; charset=utf-8";

/// A compiled-in text file, served with `content_type`.
///
/// ```
/// use hil_http::page::{CSS, PAGE_CSS, asset};
/// let r = asset(PAGE_CSS, CSS);
/// assert_eq!((r.status, r.content_type), (200, CSS));
/// ```
pub fn asset(text: &'static str, content_type: &'static str) -> Response {
    Response {
        status: 200,
        content_type,
        body: text.as_bytes().to_vec(),
    }
}

/// A picture file and its content type.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Picture {
    /// The file's bytes.
    pub bytes: Vec<u8>,
    /// Its content type, from its extension.
    pub content_type: &'static str,
}

impl Picture {
    /// The picture as a 200 response.
    pub fn response(&self) -> Response {
        Response {
            status: 200,
            content_type: self.content_type,
            body: self.bytes.clone(),
        }
    }
}

/// The picture of `name` in `dir` (`<name>.png`, `.jpg`, `.jpeg` or
/// `.webp`, first found), if there is one. Names that are not plain
/// (letters, digits, `_`, `-`) never map to a file. SVG is not served: it
/// can carry scripts. A picture that is not a regular file or is larger
/// than `hil_core::files::limits::ASSET` is an error naming the file, not
/// a page without its picture.
pub fn find_picture(dir: &Path, name: &str) -> hil_core::Result<Option<Picture>> {
    if name.is_empty()
        || !name
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
    {
        return Ok(None);
    }
    for (ext, content_type) in [
        ("png", "image/png"),
        ("jpg", "image/jpeg"),
        ("jpeg", "image/jpeg"),
        ("webp", "image/webp"),
    ] {
        let path = dir.join(format!("{name}.{ext}"));
        if !path.exists() {
            continue;
        }
        let bytes = hil_core::files::read_bytes(&path, hil_core::files::limits::ASSET)?;
        return Ok(Some(Picture {
            bytes,
            content_type,
        }));
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pictures_are_found_by_plain_names_only() {
        let dir = std::env::temp_dir().join(format!("hil-http-pictures-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("carrot.jpg"), b"jpeg bytes").unwrap();
        std::fs::write(dir.join("bad.svg"), b"<svg/>").unwrap();
        let carrot = find_picture(&dir, "carrot").unwrap().unwrap();
        assert_eq!(carrot.content_type, "image/jpeg");
        assert_eq!(carrot.bytes, b"jpeg bytes");
        assert_eq!(find_picture(&dir, "bad").unwrap(), None, "no SVG");
        assert_eq!(find_picture(&dir, "../carrot").unwrap(), None);
        assert_eq!(find_picture(&dir, "").unwrap(), None);
        // A folder where a picture should be is an error naming it.
        std::fs::create_dir_all(dir.join("pea.png")).unwrap();
        let err = find_picture(&dir, "pea").unwrap_err().to_string();
        assert!(err.contains("pea.png"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
