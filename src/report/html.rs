//! A self-contained HTML page: styles inline and every picture a data URI,
//! so the one file opens from disk, is mailed or archived whole, and needs
//! no network.

use base64::Engine;
use base64::engine::general_purpose::STANDARD;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write;

/// Text made safe inside HTML elements and attribute values.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

const STYLE: &str = "body{font-family:'DejaVu Sans',Helvetica,Arial,sans-serif;max-width:1000px;margin:2em auto;\
padding:0 1em;color:#222;line-height:1.45}h1{font-size:1.6em}h2{border-bottom:1px solid #ddd;padding-bottom:.2em;\
margin-top:2em}table{border-collapse:collapse;margin:1em 0;font-size:.92em}td,th{border:1px solid #ccc;\
padding:.25em .6em;text-align:right}th{background:#f4f4f4}td:first-child,th:first-child{text-align:left}\
figure{margin:1em 0}figure img{max-width:100%;border:1px solid #eee}figcaption{font-size:.9em;color:#555}\
.numbers{display:flex;gap:1em;flex-wrap:wrap}.number{border:1px solid #ddd;border-radius:6px;padding:.6em 1em;\
min-width:10em}.number b{display:block;font-size:1.6em}.number span{font-size:.85em;color:#555}\
.muted{color:#777;font-size:.9em}";

/// Marks the page `data-images-ok="true"` once every image has loaded with
/// a size, `"false"` if any failed: a headless browser reads it back.
const IMAGE_CHECK: &str = "window.addEventListener('load',function(){var ok=Array.prototype.every.call(\
document.images,function(i){return i.complete&&i.naturalWidth>0});document.body.setAttribute('data-images-ok',\
ok?'true':'false')});";

/// A page being written, section by section.
pub struct Page {
    title: String,
    body: String,
}

impl Page {
    pub fn new(title: &str) -> Page {
        let mut page = Page { title: title.to_string(), body: String::new() };
        page.push(&format!("<h1>{}</h1>\n", escape(title)));
        page
    }

    fn push(&mut self, html: &str) {
        self.body.push_str(html);
    }

    pub fn heading(&mut self, text: &str) {
        self.push(&format!("<h2>{}</h2>\n", escape(text)));
    }

    pub fn paragraph(&mut self, text: &str) {
        self.push(&format!("<p>{}</p>\n", escape(text)));
    }

    pub fn note(&mut self, text: &str) {
        self.push(&format!("<p class=\"muted\">{}</p>\n", escape(text)));
    }

    /// Preformatted text, such as settings as JSON.
    pub fn code(&mut self, text: &str) {
        self.push(&format!("<pre>{}</pre>\n", escape(text)));
    }

    /// Headline numbers, each a value, a caption, and where the value is in
    /// `metrics.json` (a key or a JSON pointer, kept in a `data-metric`
    /// attribute so the page can be checked against the file).
    pub fn numbers(&mut self, numbers: &[(String, String, String)]) {
        let mut html = String::from("<div class=\"numbers\">");
        for (value, caption, key) in numbers {
            write!(
                html,
                "<div class=\"number\"><b data-metric=\"{}\">{}</b><span>{}</span></div>",
                escape(key),
                escape(value),
                escape(caption)
            )
            .expect("writing to a string cannot fail");
        }
        html.push_str("</div>\n");
        self.push(&html);
    }

    /// A table; cells are text.
    pub fn table(&mut self, header: &[String], rows: &[Vec<String>]) {
        let mut html = String::from("<table><tr>");
        for h in header {
            write!(html, "<th>{}</th>", escape(h)).expect("writing to a string cannot fail");
        }
        html.push_str("</tr>");
        for row in rows {
            html.push_str("<tr>");
            for cell in row {
                write!(html, "<td>{}</td>", escape(cell)).expect("writing to a string cannot fail");
            }
            html.push_str("</tr>");
        }
        html.push_str("</table>\n");
        self.push(&html);
    }

    /// A picture (`mime` such as `image/png`) with its caption.
    pub fn image(&mut self, bytes: &[u8], mime: &str, alt: &str, caption: &str) {
        self.push(&format!(
            "<figure><img src=\"data:{mime};base64,{}\" alt=\"{}\"><figcaption>{}</figcaption></figure>\n",
            STANDARD.encode(bytes),
            escape(alt),
            escape(caption)
        ));
    }

    /// The confusion matrix, true activities down and named activities
    /// across, each cell shaded by its share of the row.
    pub fn confusion(&mut self, confusion: &BTreeMap<String, BTreeMap<String, usize>>) {
        let named: BTreeSet<&String> = confusion.values().flat_map(|r| r.keys()).collect();
        let mut html = String::from("<table><tr><th>true \\ named</th>");
        for n in &named {
            write!(html, "<th>{}</th>", escape(n)).expect("writing to a string cannot fail");
        }
        html.push_str("</tr>");
        for (truth, row) in confusion {
            let total: usize = row.values().sum();
            write!(html, "<tr><th>{}</th>", escape(truth)).expect("writing to a string cannot fail");
            for n in &named {
                let count = row.get(*n).copied().unwrap_or(0);
                let share = if total > 0 { count as f64 / total as f64 } else { 0.0 };
                write!(html, "<td style=\"background:rgba(31,119,180,{:.2})\">{count}</td>", 0.6 * share)
                    .expect("writing to a string cannot fail");
            }
            html.push_str("</tr>");
        }
        html.push_str("</table>\n");
        self.push(&html);
    }

    /// The whole document.
    pub fn finish(self) -> String {
        format!(
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>\n\
             <style>{STYLE}</style>\n<script>{IMAGE_CHECK}</script>\n</head>\n<body>\n{}</body>\n</html>\n",
            escape(&self.title),
            self.body
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_escaped_and_images_are_inline() {
        let mut page = Page::new("a <b> & \"c\"");
        page.image(&[1, 2, 3], "image/png", "x", "y");
        page.numbers(&[("12.5".into(), "upper body (mm)".into(), "upper_body_mm".into())]);
        let html = page.finish();
        assert!(html.contains("<title>a &lt;b&gt; &amp; &quot;c&quot;</title>"));
        assert!(html.contains("src=\"data:image/png;base64,AQID\""));
        assert!(html.contains("<b data-metric=\"upper_body_mm\">12.5</b>"));
        assert!(!html.contains("http://") && !html.contains("https://"), "the page must not reach the network");
    }
}
