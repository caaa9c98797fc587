//! A reader of the S-expressions KiCad writes (`(footprint "Lib:Name" (at 1 2 90) …)`), with the
//! line of every node so that errors can point at it.
//!
//! Atoms are bare words or double-quoted strings (with `\"`, `\\`, `\n` escapes). Nesting is
//! limited to [`MAX_DEPTH`] so that no input can exhaust the stack, and the whole text is read
//! by the caller with a size limit.

/// Deepest nesting accepted (KiCad files nest about 10 deep).
pub const MAX_DEPTH: usize = 200;

/// One node of the tree.
#[derive(Clone, Debug, PartialEq)]
pub enum Node {
    /// A bare word or quoted string, with its 1-based line.
    Atom(String, usize),
    /// `( … )`, with the line of its opening parenthesis.
    List(Vec<Node>, usize),
}

/// Where and why the text is not an S-expression.
#[derive(Clone, Debug, PartialEq)]
pub struct SexprError {
    /// 1-based line.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

impl Node {
    /// The line the node starts on.
    pub fn line(&self) -> usize {
        match self {
            Node::Atom(_, l) | Node::List(_, l) => *l,
        }
    }

    /// The atom's text.
    pub fn atom(&self) -> Option<&str> {
        match self {
            Node::Atom(s, _) => Some(s),
            Node::List(..) => None,
        }
    }

    /// The list's items.
    pub fn items(&self) -> &[Node] {
        match self {
            Node::List(items, _) => items,
            Node::Atom(..) => &[],
        }
    }

    /// The head word of a list (`footprint` in `(footprint …)`).
    pub fn head(&self) -> Option<&str> {
        self.items().first().and_then(Node::atom)
    }

    /// The child lists whose head is `name`.
    pub fn children<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a Node> + 'a {
        self.items().iter().filter(move |n| n.head() == Some(name))
    }

    /// The first child list whose head is `name`.
    pub fn child(&self, name: &str) -> Option<&Node> {
        self.items().iter().find(|n| n.head() == Some(name))
    }

    /// The `i`-th item after the head, as an atom.
    pub fn arg(&self, i: usize) -> Option<&str> {
        self.items().get(i + 1).and_then(Node::atom)
    }

    /// The atoms after the head.
    pub fn args(&self) -> impl Iterator<Item = &str> {
        self.items().iter().skip(1).filter_map(Node::atom)
    }
}

/// Parses the whole text: exactly one top-level list (leading and trailing white space allowed).
pub fn parse(text: &str) -> Result<Node, SexprError> {
    let mut p = Parser {
        bytes: text.as_bytes(),
        text,
        at: 0,
        line: 1,
    };
    p.skip_space();
    if p.peek() != Some(b'(') {
        return Err(p.error("expected `(` at the start of the file"));
    }
    let root = p.list()?;
    p.skip_space();
    if p.at < p.bytes.len() {
        return Err(p.error("text after the closing `)` of the file"));
    }
    Ok(root)
}

struct Parser<'a> {
    bytes: &'a [u8],
    text: &'a str,
    at: usize,
    line: usize,
}

impl Parser<'_> {
    fn error(&self, message: &str) -> SexprError {
        SexprError {
            line: self.line,
            message: message.to_string(),
        }
    }

    fn peek(&self) -> Option<u8> {
        self.bytes.get(self.at).copied()
    }

    fn skip_space(&mut self) {
        while let Some(b) = self.peek() {
            match b {
                b'\n' => self.line += 1,
                b' ' | b'\t' | b'\r' => {}
                _ => break,
            }
            self.at += 1;
        }
    }

    /// A list, iteratively (an explicit stack, so deep input cannot overflow ours).
    fn list(&mut self) -> Result<Node, SexprError> {
        let mut stack: Vec<(Vec<Node>, usize)> = Vec::new();
        loop {
            self.skip_space();
            match self.peek() {
                None => {
                    let open = stack.last().map_or(self.line, |s| s.1);
                    return Err(SexprError {
                        line: self.line,
                        message: format!("the file ends inside the list opened on line {open}"),
                    });
                }
                Some(b'(') => {
                    if stack.len() >= MAX_DEPTH {
                        return Err(self.error(&format!("lists nested deeper than {MAX_DEPTH}")));
                    }
                    stack.push((Vec::new(), self.line));
                    self.at += 1;
                }
                Some(b')') => {
                    self.at += 1;
                    let Some((items, line)) = stack.pop() else {
                        return Err(self.error("`)` without an opening `(`"));
                    };
                    let node = Node::List(items, line);
                    match stack.last_mut() {
                        Some(parent) => parent.0.push(node),
                        None => return Ok(node),
                    }
                }
                Some(b'"') => {
                    let atom = self.quoted()?;
                    match stack.last_mut() {
                        Some(parent) => parent.0.push(atom),
                        None => return Err(self.error("a string outside any list")),
                    }
                }
                Some(_) => {
                    let start = self.at;
                    while let Some(b) = self.peek() {
                        if matches!(b, b' ' | b'\t' | b'\r' | b'\n' | b'(' | b')' | b'"') {
                            break;
                        }
                        self.at += 1;
                    }
                    let atom = Node::Atom(self.text[start..self.at].to_string(), self.line);
                    match stack.last_mut() {
                        Some(parent) => parent.0.push(atom),
                        None => return Err(self.error("a word outside any list")),
                    }
                }
            }
        }
    }

    fn quoted(&mut self) -> Result<Node, SexprError> {
        let line = self.line;
        self.at += 1;
        let mut out = String::new();
        let mut run = self.at;
        loop {
            match self.peek() {
                None => {
                    return Err(SexprError {
                        line,
                        message: "a string that is never closed".into(),
                    });
                }
                Some(b'"') => {
                    out.push_str(&self.text[run..self.at]);
                    self.at += 1;
                    return Ok(Node::Atom(out, line));
                }
                Some(b'\\') => {
                    out.push_str(&self.text[run..self.at]);
                    self.at += 1;
                    match self.peek() {
                        Some(b'n') => out.push('\n'),
                        Some(b't') => out.push('\t'),
                        Some(b'"') => out.push('"'),
                        Some(b'\\') => out.push('\\'),
                        Some(b'\n') => {
                            self.line += 1;
                            out.push('\n');
                        }
                        Some(_) => {
                            // Any other escaped character stands for itself (a whole UTF-8
                            // character, so that slicing stays on boundaries).
                            let ch = self.text[self.at..].chars().next().unwrap_or('\\');
                            out.push(ch);
                            self.at += ch.len_utf8() - 1;
                        }
                        None => continue,
                    }
                    self.at += 1;
                    run = self.at;
                }
                Some(b'\n') => {
                    self.line += 1;
                    self.at += 1;
                }
                Some(_) => self.at += 1,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_nested_lists_with_lines_and_strings() {
        let text = "(kicad_pcb (version 20240108)\n  (footprint \"Lib:R_0402\" (at 1.5 -2 90)\n (property \"Value\" \"10 \\\"k\\\"\")))";
        let root = parse(text).unwrap();
        assert_eq!(root.head(), Some("kicad_pcb"));
        let fp = root.child("footprint").unwrap();
        assert_eq!(fp.line(), 2);
        assert_eq!(fp.arg(0), Some("Lib:R_0402"));
        let at: Vec<&str> = fp.child("at").unwrap().args().collect();
        assert_eq!(at, ["1.5", "-2", "90"]);
        let value = fp.child("property").unwrap();
        assert_eq!(value.arg(1), Some("10 \"k\""));
        assert_eq!(value.line(), 3);
    }

    #[test]
    fn refuses_broken_text_with_its_line() {
        assert_eq!(parse("(a (b c)\n(d").unwrap_err().line, 2);
        assert!(parse("(a \"open\n").unwrap_err().message.contains("never closed"));
        assert!(parse("(a))").unwrap_err().message.contains("after the closing"));
        assert!(parse("word").unwrap_err().message.contains("expected `(`"));
        let deep = "(".repeat(MAX_DEPTH + 5);
        assert!(parse(&deep).unwrap_err().message.contains("nested deeper"));
        // Multi-byte characters after an escape keep the slicing on boundaries.
        let root = parse("(a \"\\é b\")").unwrap();
        assert_eq!(root.arg(0), Some("é b"));
    }
}
