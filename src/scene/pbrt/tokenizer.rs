//! pbrt-v4 tokenizer: words, quoted strings, numbers, brackets; `#` comments to end of line.
//! Every token carries its `file:line:column` so errors can point at the exact spot.

use anyhow::anyhow;
use std::fmt;
use std::sync::Arc;

/// A position in a scene file (1-based line and column).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Loc {
    /// File name as given (shared by every token of the file).
    pub file: Arc<str>,
    /// 1-based line.
    pub line: u32,
    /// 1-based column (in bytes).
    pub col: u32,
}

impl fmt::Display for Loc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.file, self.line, self.col)
    }
}

impl Loc {
    /// `file:line` (for warnings, where the column adds nothing).
    pub fn file_line(&self) -> String {
        format!("{}:{}", self.file, self.line)
    }
}

/// An error at `loc`, formatted `file:line:column: msg`.
pub fn err_at(loc: &Loc, msg: impl fmt::Display) -> anyhow::Error {
    anyhow!("{loc}: {msg}")
}

/// What a token is.
#[derive(Clone, Debug, PartialEq)]
pub enum Tok {
    /// A bare word: directive names, `true`/`false`.
    Word(String),
    /// A quoted string (escapes resolved).
    Str(String),
    /// A finite number.
    Num(f64),
    /// `[`
    Open,
    /// `]`
    Close,
}

impl Tok {
    /// Short human description for "expected X, found Y" messages.
    pub fn describe(&self) -> String {
        match self {
            Tok::Word(w) => format!("'{w}'"),
            Tok::Str(s) => format!("string \"{s}\""),
            Tok::Num(n) => format!("number {n}"),
            Tok::Open => "'['".into(),
            Tok::Close => "']'".into(),
        }
    }
}

/// A token and where it starts.
#[derive(Clone, Debug, PartialEq)]
pub struct Token {
    /// The token.
    pub tok: Tok,
    /// Where it starts.
    pub loc: Loc,
}

/// Streams tokens from one file's text.
pub struct Tokenizer {
    file: Arc<str>,
    src: Vec<u8>,
    pos: usize,
    line: u32,
    line_start: usize,
    peeked: Option<Token>,
}

fn is_delim(c: u8) -> bool {
    c.is_ascii_whitespace() || matches!(c, b'[' | b']' | b'"' | b'#')
}

impl Tokenizer {
    /// Tokenize `src`, reporting positions against `file`.
    pub fn new(file: impl Into<Arc<str>>, src: impl Into<Vec<u8>>) -> Self {
        Self {
            file: file.into(),
            src: src.into(),
            pos: 0,
            line: 1,
            line_start: 0,
            peeked: None,
        }
    }

    /// The file name tokens are reported against.
    pub fn file(&self) -> &Arc<str> {
        &self.file
    }

    /// The current position (end of the last token consumed).
    pub fn here(&self) -> Loc {
        Loc {
            file: self.file.clone(),
            line: self.line,
            col: (self.pos - self.line_start + 1) as u32,
        }
    }

    /// Look at the next token without consuming it.
    pub fn peek(&mut self) -> anyhow::Result<Option<&Token>> {
        if self.peeked.is_none() {
            self.peeked = self.lex()?;
        }
        Ok(self.peeked.as_ref())
    }

    /// Consume the next token (`None` at end of file).
    pub fn next_token(&mut self) -> anyhow::Result<Option<Token>> {
        if let Some(t) = self.peeked.take() {
            return Ok(Some(t));
        }
        self.lex()
    }

    fn skip_space_and_comments(&mut self) {
        while self.pos < self.src.len() {
            let c = self.src[self.pos];
            if c == b'\n' {
                self.pos += 1;
                self.line += 1;
                self.line_start = self.pos;
            } else if c.is_ascii_whitespace() {
                self.pos += 1;
            } else if c == b'#' {
                while self.pos < self.src.len() && self.src[self.pos] != b'\n' {
                    self.pos += 1;
                }
            } else {
                break;
            }
        }
    }

    fn lex(&mut self) -> anyhow::Result<Option<Token>> {
        self.skip_space_and_comments();
        if self.pos >= self.src.len() {
            return Ok(None);
        }
        let loc = self.here();
        let c = self.src[self.pos];
        let tok = match c {
            b'[' => {
                self.pos += 1;
                Tok::Open
            }
            b']' => {
                self.pos += 1;
                Tok::Close
            }
            b'"' => Tok::Str(self.lex_string(&loc)?),
            _ => {
                let start = self.pos;
                while self.pos < self.src.len() && !is_delim(self.src[self.pos]) {
                    self.pos += 1;
                }
                let text = std::str::from_utf8(&self.src[start..self.pos])
                    .map_err(|_| err_at(&loc, "invalid UTF-8 in token"))?;
                if c.is_ascii_alphabetic() || c == b'_' {
                    Tok::Word(text.to_string())
                } else if c.is_ascii_digit() || matches!(c, b'-' | b'+' | b'.') {
                    match text.parse::<f64>() {
                        Ok(v) if v.is_finite() => Tok::Num(v),
                        _ => {
                            return Err(err_at(&loc, format!("expected a number, found '{text}'")));
                        }
                    }
                } else {
                    return Err(err_at(
                        &loc,
                        format!(
                            "unexpected character '{}'",
                            text.chars().next().unwrap_or('?')
                        ),
                    ));
                }
            }
        };
        Ok(Some(Token { tok, loc }))
    }

    fn lex_string(&mut self, loc: &Loc) -> anyhow::Result<String> {
        self.pos += 1; // opening quote
        let mut out = Vec::new();
        loop {
            let Some(&c) = self.src.get(self.pos) else {
                return Err(err_at(loc, "unterminated string (end of file)"));
            };
            self.pos += 1;
            match c {
                b'"' => break,
                b'\n' => return Err(err_at(loc, "unterminated string (newline inside quotes)")),
                b'\\' => {
                    let Some(&e) = self.src.get(self.pos) else {
                        return Err(err_at(loc, "unterminated string (end of file)"));
                    };
                    self.pos += 1;
                    out.push(match e {
                        b'n' => b'\n',
                        b't' => b'\t',
                        b'r' => b'\r',
                        b'b' => 8,
                        b'f' => 12,
                        other => other,
                    });
                }
                _ => out.push(c),
            }
        }
        String::from_utf8(out).map_err(|_| err_at(loc, "invalid UTF-8 in string"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn toks(s: &str) -> Vec<Tok> {
        let mut t = Tokenizer::new("t.pbrt", s);
        let mut v = Vec::new();
        while let Some(x) = t.next_token().unwrap() {
            v.push(x.tok);
        }
        v
    }

    #[test]
    fn tokens_of_every_kind() {
        assert_eq!(
            toks("Shape \"sphere\" [ 1 -2.5e1 .5 ] # comment [ \n true"),
            vec![
                Tok::Word("Shape".into()),
                Tok::Str("sphere".into()),
                Tok::Open,
                Tok::Num(1.0),
                Tok::Num(-25.0),
                Tok::Num(0.5),
                Tok::Close,
                Tok::Word("true".into()),
            ]
        );
    }

    #[test]
    fn brackets_need_no_spaces_and_escapes_resolve() {
        assert_eq!(
            toks("[1 2]\"a\\\"b\""),
            vec![
                Tok::Open,
                Tok::Num(1.0),
                Tok::Num(2.0),
                Tok::Close,
                Tok::Str("a\"b".into())
            ]
        );
    }

    #[test]
    fn locations_are_line_and_column() {
        let mut t = Tokenizer::new("f.pbrt", "A\n  B # x\n\tC");
        let cols: Vec<(u32, u32)> = std::iter::from_fn(|| t.next_token().unwrap())
            .map(|x| (x.loc.line, x.loc.col))
            .collect();
        assert_eq!(cols, vec![(1, 1), (2, 3), (3, 2)]);
    }

    #[test]
    fn bad_tokens_are_errors_with_location() {
        for (src, what) in [
            ("\n \"abc", "f.pbrt:2:2: unterminated string"),
            ("1.2.3", "f.pbrt:1:1: expected a number"),
            ("-1e999", "expected a number"),
            ("  @", "f.pbrt:1:3: unexpected character"),
            ("\"a\nb\"", "unterminated string"),
        ] {
            let mut t = Tokenizer::new("f.pbrt", src);
            let e = loop {
                match t.next_token() {
                    Ok(Some(_)) => continue,
                    Ok(None) => panic!("no error for {src:?}"),
                    Err(e) => break e.to_string(),
                }
            };
            assert!(e.contains(what), "{src:?}: {e}");
        }
    }
}
