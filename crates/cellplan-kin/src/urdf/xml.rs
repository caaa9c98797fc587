//! A small XML scanner: checks well-formedness and keeps every element with its line, so
//! URDF errors can point at a line (urdf-rs does not report lines).

/// One element of the document.
#[derive(Debug)]
pub(crate) struct Element {
    pub name: String,
    pub attrs: Vec<(String, String)>,
    /// 1-based line of the `<`.
    pub line: usize,
    pub children: Vec<usize>,
}

impl Element {
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }
}

/// A parsed document; element 0 is the root.
#[derive(Debug)]
pub(crate) struct Document {
    pub elements: Vec<Element>,
}

impl Document {
    pub fn root(&self) -> &Element {
        &self.elements[0]
    }
    pub fn children<'a>(&'a self, e: &'a Element) -> impl Iterator<Item = &'a Element> + 'a {
        e.children.iter().filter_map(|&i| self.elements.get(i))
    }
    pub fn child<'a>(&'a self, e: &'a Element, name: &str) -> Option<&'a Element> {
        self.children(e).find(|c| c.name == name)
    }
}

/// A well-formedness error: 1-based line and message.
pub(crate) type XmlError = (usize, String);

struct Scanner<'a> {
    s: &'a [u8],
    pos: usize,
    line: usize,
}

fn is_name_byte(b: u8) -> bool {
    b.is_ascii_alphanumeric() || matches!(b, b'_' | b'-' | b'.' | b':') || b >= 0x80
}

impl<'a> Scanner<'a> {
    fn peek(&self) -> Option<u8> {
        self.s.get(self.pos).copied()
    }
    fn starts_with(&self, pat: &str) -> bool {
        self.s[self.pos..].starts_with(pat.as_bytes())
    }
    fn bump(&mut self) {
        if self.s.get(self.pos) == Some(&b'\n') {
            self.line += 1;
        }
        self.pos += 1;
    }
    fn advance(&mut self, n: usize) {
        for _ in 0..n {
            self.bump();
        }
    }
    /// Skips past `end`; error naming `what` (opened at `line`) when missing.
    fn skip_past(&mut self, end: &str, what: &str, line: usize) -> Result<(), XmlError> {
        while self.pos < self.s.len() {
            if self.starts_with(end) {
                self.advance(end.len());
                return Ok(());
            }
            self.bump();
        }
        Err((line, format!("{what} is never closed (expected `{end}`)")))
    }
    fn skip_ws(&mut self) {
        while matches!(self.peek(), Some(b' ' | b'\t' | b'\r' | b'\n')) {
            self.bump();
        }
    }
    fn name(&mut self) -> Option<String> {
        let start = self.pos;
        while self.peek().is_some_and(is_name_byte) {
            self.bump();
        }
        (self.pos > start).then(|| String::from_utf8_lossy(&self.s[start..self.pos]).into_owned())
    }
}

fn unescape(v: &str) -> String {
    if !v.contains('&') {
        return v.to_string();
    }
    v.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&amp;", "&")
}

/// Parses `text`; the error carries the line where the problem shows.
pub(crate) fn parse(text: &str) -> Result<Document, XmlError> {
    let mut p = Parser {
        sc: Scanner {
            s: text.as_bytes(),
            pos: 0,
            line: 1,
        },
        elements: Vec::new(),
        stack: Vec::new(),
        root_closed: false,
    };
    // A byte-order mark is allowed.
    if p.sc.starts_with("\u{feff}") {
        p.sc.pos += 3;
    }
    while p.sc.pos < p.sc.s.len() {
        p.step()?;
    }
    p.finish()
}

/// The state of [`parse`]: the scanner, the elements so far and the open ones.
struct Parser<'a> {
    sc: Scanner<'a>,
    elements: Vec<Element>,
    /// The open elements, innermost last.
    stack: Vec<usize>,
    root_closed: bool,
}

impl Parser<'_> {
    /// Reads what starts at the current position: a comment, CDATA, a processing instruction,
    /// a declaration, a closing or opening tag, or one byte of text.
    fn step(&mut self) -> Result<(), XmlError> {
        let sc = &mut self.sc;
        let line = sc.line;
        if sc.starts_with("<!--") {
            sc.skip_past("-->", "comment", line)
        } else if sc.starts_with("<![CDATA[") {
            if self.stack.is_empty() {
                return Err((line, "CDATA outside the root element".into()));
            }
            sc.skip_past("]]>", "CDATA section", line)
        } else if sc.starts_with("<?") {
            sc.skip_past("?>", "processing instruction", line)
        } else if sc.starts_with("<!") {
            self.declaration(line)
        } else if sc.starts_with("</") {
            self.close_tag(line)
        } else if sc.peek() == Some(b'<') {
            self.open_tag(line)
        } else {
            let b = sc.peek().unwrap_or(b' ');
            if self.stack.is_empty() && !b.is_ascii_whitespace() {
                return Err((line, "text outside the root element".into()));
            }
            sc.bump();
            Ok(())
        }
    }

    /// Skips a `<!...>` declaration (DOCTYPE), possibly with an internal subset in brackets.
    fn declaration(&mut self, line: usize) -> Result<(), XmlError> {
        let sc = &mut self.sc;
        let mut depth = 0i32;
        loop {
            match sc.peek() {
                None => return Err((line, "declaration `<!...` is never closed".into())),
                Some(b'[') => depth += 1,
                Some(b']') => depth -= 1,
                Some(b'>') if depth <= 0 => {
                    sc.bump();
                    return Ok(());
                }
                _ => {}
            }
            sc.bump();
        }
    }

    /// Reads `</name>` and closes the innermost open element, which must be `name`.
    fn close_tag(&mut self, line: usize) -> Result<(), XmlError> {
        let sc = &mut self.sc;
        sc.advance(2);
        let name = sc
            .name()
            .ok_or((line, "expected a tag name after `</`".to_string()))?;
        sc.skip_ws();
        if sc.peek() != Some(b'>') {
            return Err((sc.line, format!("expected `>` to close `</{name}`")));
        }
        sc.bump();
        let Some(open) = self.stack.pop() else {
            return Err((line, format!("closing tag `</{name}>` without an opening tag")));
        };
        let e = &self.elements[open];
        if e.name != name {
            return Err((
                line,
                format!(
                    "closing tag `</{name}>` does not match `<{}>` opened on line {}",
                    e.name, e.line
                ),
            ));
        }
        if self.stack.is_empty() {
            self.root_closed = true;
        }
        Ok(())
    }

    /// Reads `<name attr="value" ...>` or `<name ... />` and adds the element under the
    /// innermost open one (opening it unless self-closing).
    fn open_tag(&mut self, line: usize) -> Result<(), XmlError> {
        self.sc.bump();
        let name = self
            .sc
            .name()
            .ok_or((line, "expected a tag name after `<`".to_string()))?;
        if self.root_closed || (self.stack.is_empty() && !self.elements.is_empty()) {
            return Err((line, format!("element `<{name}>` after the root element ended")));
        }
        let mut attrs: Vec<(String, String)> = Vec::new();
        let self_closing = loop {
            let had_ws = matches!(self.sc.peek(), Some(b' ' | b'\t' | b'\r' | b'\n'));
            if let Some(closing) = self.tag_end(line, &name)? {
                break closing;
            }
            let (key, at, value) = self.attribute(&name, had_ws)?;
            if attrs.iter().any(|(k, _)| *k == key) {
                return Err((at, format!("attribute `{key}` appears twice in `<{name}>`")));
            }
            attrs.push((key, unescape(&value)));
        };
        let idx = self.elements.len();
        self.elements.push(Element {
            name,
            attrs,
            line,
            children: Vec::new(),
        });
        if let Some(&parent) = self.stack.last() {
            self.elements[parent].children.push(idx);
        }
        if self_closing {
            if self.stack.is_empty() {
                self.root_closed = true;
            }
        } else {
            self.stack.push(idx);
        }
        Ok(())
    }

    /// After white space: `Some(false)` past `>`, `Some(true)` past `/>`, `None` when an
    /// attribute follows.
    fn tag_end(&mut self, line: usize, name: &str) -> Result<Option<bool>, XmlError> {
        let sc = &mut self.sc;
        sc.skip_ws();
        match sc.peek() {
            None => Err((line, format!("tag `<{name}` is never closed"))),
            Some(b'>') => {
                sc.bump();
                Ok(Some(false))
            }
            Some(b'/') => {
                sc.bump();
                if sc.peek() != Some(b'>') {
                    return Err((sc.line, format!("expected `>` after `/` in `<{name}`")));
                }
                sc.bump();
                Ok(Some(true))
            }
            _ => Ok(None),
        }
    }

    /// One attribute `key="value"` of tag `name` (`had_ws`: white space came before it), as
    /// (key, its line, raw value).
    fn attribute(&mut self, name: &str, had_ws: bool) -> Result<(String, usize, String), XmlError> {
        let sc = &mut self.sc;
        let at = sc.line;
        let Some(key) = sc.name() else {
            return Err((at, format!("unexpected character in tag `<{name}`")));
        };
        if !had_ws {
            return Err((
                at,
                format!("attribute `{key}` of `<{name}>` needs a space before it"),
            ));
        }
        sc.skip_ws();
        if sc.peek() != Some(b'=') {
            return Err((at, format!("attribute `{key}` of `<{name}>` has no `=\"value\"`")));
        }
        sc.bump();
        sc.skip_ws();
        let quote = match sc.peek() {
            Some(q @ (b'"' | b'\'')) => q,
            _ => {
                return Err((
                    sc.line,
                    format!("value of attribute `{key}` of `<{name}>` must be quoted"),
                ));
            }
        };
        sc.bump();
        let start = sc.pos;
        while sc.peek().is_some_and(|b| b != quote) {
            if sc.peek() == Some(b'<') {
                return Err((sc.line, format!("`<` inside the value of attribute `{key}`")));
            }
            sc.bump();
        }
        if sc.peek().is_none() {
            return Err((at, format!("value of attribute `{key}` is never closed")));
        }
        let value = String::from_utf8_lossy(&sc.s[start..sc.pos]).into_owned();
        sc.bump();
        Ok((key, at, value))
    }

    /// The document, once every element is closed and there is one.
    fn finish(self) -> Result<Document, XmlError> {
        if let Some(&open) = self.stack.last() {
            let e = &self.elements[open];
            return Err((
                self.sc.line,
                format!("element `<{}>` opened on line {} is never closed", e.name, e.line),
            ));
        }
        if self.elements.is_empty() {
            return Err((1, "no XML element found".into()));
        }
        Ok(Document {
            elements: self.elements,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_nested_elements_with_lines() {
        let doc = parse("<?xml version=\"1.0\"?>\n<!-- c -->\n<a x=\"1\">\n  <b y='2'/>\n  <c>t</c>\n</a>\n")
            .unwrap();
        let root = doc.root();
        assert_eq!(root.name, "a");
        assert_eq!(root.line, 3);
        assert_eq!(root.attr("x"), Some("1"));
        let kids: Vec<_> = doc.children(root).map(|e| (e.name.as_str(), e.line)).collect();
        assert_eq!(kids, vec![("b", 4), ("c", 5)]);
        assert_eq!(doc.child(root, "b").and_then(|b| b.attr("y")), Some("2"));
    }

    #[test]
    fn reports_lines_of_errors() {
        assert_eq!(parse("<a>\n<b>\n</a>").unwrap_err().0, 3);
        assert_eq!(parse("<a>\n<b x=1/>\n</a>").unwrap_err().0, 2);
        assert_eq!(parse("<a>\n\n<b>").unwrap_err().0, 3);
        assert_eq!(parse("<a/>\n<b/>").unwrap_err().0, 2);
        assert_eq!(parse("hello").unwrap_err().0, 1);
        assert_eq!(parse("<a>\n<!-- x").unwrap_err().0, 2);
        assert_eq!(parse("<a x=\"1\" x=\"2\"/>").unwrap_err().0, 1);
        assert!(parse("").is_err());
    }
}
