//! The HIERARCHY section: ROOT / JOINT / End Site blocks with OFFSET and CHANNELS.
//!
//! In: the lines before `MOTION`. Out: the joints in file order (parents first), each with
//! its offset, channels and the index of its first channel in a frame line. Every rule a
//! file can break is reported with its line.

use super::error::{BvhError, BvhErrorKind};
use super::parse::{BvhJoint, Channel};
use super::text::{Token, parse_number, tokenize};
use glam::Vec3;

/// Deepest accepted joint nesting (real rigs stay under 30; the parser recurses per level).
pub const MAX_JOINT_DEPTH: usize = 256;

/// Parses the hierarchy lines (`lines[0]` is line 1 of the file).
pub fn parse_hierarchy(origin: &str, lines: &[&str]) -> Result<Vec<BvhJoint>, BvhError> {
    let tokens = tokenize(lines.iter().enumerate().map(|(i, l)| (i + 1, *l)));
    let mut parser = Parser {
        origin,
        tokens: &tokens,
        pos: 0,
        joints: Vec::new(),
        channels: 0,
        depth: 0,
    };
    parser.document()?;
    Ok(parser.joints)
}

struct Parser<'t, 'a> {
    origin: &'t str,
    tokens: &'t [Token<'a>],
    pos: usize,
    joints: Vec<BvhJoint>,
    /// Channels declared so far (the next joint's first channel index).
    channels: usize,
    /// Joints open around the current one.
    depth: usize,
}

impl<'a> Parser<'_, 'a> {
    fn document(&mut self) -> Result<(), BvhError> {
        match self.next() {
            Some(t) if t.text.eq_ignore_ascii_case("HIERARCHY") => {}
            Some(t) => return Err(self.err(t.line, BvhErrorKind::MissingHierarchy(t.text.into()))),
            None => return Err(self.err(1, BvhErrorKind::MissingHierarchy("end of file".into()))),
        }
        while let Some(t) = self.next() {
            if t.text.eq_ignore_ascii_case("ROOT") {
                self.joint(t, None)?;
            } else {
                return Err(self.err(t.line, BvhErrorKind::UnknownKeyword(t.text.into())));
            }
        }
        if self.joints.is_empty() {
            return Err(self.err(self.last_line(), BvhErrorKind::NoJoints));
        }
        Ok(())
    }

    /// Parses `ROOT|JOINT name { … }` after its keyword.
    fn joint(&mut self, keyword: Token<'a>, parent: Option<usize>) -> Result<(), BvhError> {
        let name = self.name_after(keyword)?;
        self.expect_open_brace()?;
        let index = self.joints.len();
        self.joints.push(BvhJoint {
            name: name.clone(),
            parent,
            offset: Vec3::ZERO,
            channels: Vec::new(),
            first_channel: self.channels,
            end_site: false,
            line: keyword.line,
        });
        let (mut has_offset, mut has_channels) = (false, false);
        loop {
            let Some(t) = self.next() else {
                return Err(self.err(self.last_line(), BvhErrorKind::UnclosedJoint(name)));
            };
            match t.text.to_ascii_uppercase().as_str() {
                "OFFSET" => {
                    if has_offset {
                        return Err(self.err(t.line, BvhErrorKind::Duplicate(name, "OFFSET")));
                    }
                    self.joints[index].offset = self.vec3()?;
                    has_offset = true;
                }
                "CHANNELS" => {
                    if has_channels {
                        return Err(self.err(t.line, BvhErrorKind::Duplicate(name, "CHANNELS")));
                    }
                    let channels = self.channel_list()?;
                    self.joints[index].first_channel = self.channels;
                    self.channels += channels.len();
                    self.joints[index].channels = channels;
                    has_channels = true;
                }
                "JOINT" => {
                    if self.depth >= MAX_JOINT_DEPTH {
                        return Err(self.err(t.line, BvhErrorKind::TooDeep(MAX_JOINT_DEPTH)));
                    }
                    self.depth += 1;
                    self.joint(t, Some(index))?;
                    self.depth -= 1;
                }
                "END" => self.end_site(t, index)?,
                "}" => break,
                _ => return Err(self.err(t.line, BvhErrorKind::UnknownKeyword(t.text.into()))),
            }
        }
        if !has_offset {
            return Err(self.err(keyword.line, BvhErrorKind::MissingOffset(name)));
        }
        if !has_channels {
            return Err(self.err(keyword.line, BvhErrorKind::MissingChannels(name)));
        }
        Ok(())
    }

    /// Parses `End Site { OFFSET x y z }` after `End`.
    fn end_site(&mut self, keyword: Token<'a>, parent: usize) -> Result<(), BvhError> {
        match self.next() {
            Some(t) if t.line == keyword.line && t.text.eq_ignore_ascii_case("Site") => {}
            other => return Err(self.expected("`Site` after `End`", other, keyword.line)),
        }
        self.expect_open_brace()?;
        match self.next() {
            Some(t) if t.text.eq_ignore_ascii_case("OFFSET") => {}
            other => return Err(self.expected("OFFSET in End Site", other, keyword.line)),
        }
        let offset = self.vec3()?;
        match self.next() {
            Some(t) if t.text == "}" => {}
            Some(t) => {
                return Err(self.err(
                    t.line,
                    BvhErrorKind::Expected {
                        expected: "`}` closing End Site".into(),
                        found: t.text.into(),
                    },
                ));
            }
            None => {
                return Err(self.err(
                    self.last_line(),
                    BvhErrorKind::UnclosedJoint(format!("{} End Site", self.joints[parent].name)),
                ));
            }
        }
        self.joints.push(BvhJoint {
            name: format!("{} End Site", self.joints[parent].name),
            parent: Some(parent),
            offset,
            channels: Vec::new(),
            first_channel: self.channels,
            end_site: true,
            line: keyword.line,
        });
        Ok(())
    }

    /// The rest of the keyword's line is the name (names may contain spaces).
    fn name_after(&mut self, keyword: Token<'a>) -> Result<String, BvhError> {
        let mut words = Vec::new();
        while let Some(t) = self.peek() {
            if t.line != keyword.line || t.text == "{" {
                break;
            }
            words.push(t.text);
            self.pos += 1;
        }
        if words.is_empty() {
            return Err(self.err(keyword.line, BvhErrorKind::MissingName(keyword.text.into())));
        }
        Ok(words.join(" "))
    }

    fn expect_open_brace(&mut self) -> Result<(), BvhError> {
        let line = self.last_line();
        match self.next() {
            Some(t) if t.text == "{" => Ok(()),
            other => Err(self.expected("`{`", other, line)),
        }
    }

    fn vec3(&mut self) -> Result<Vec3, BvhError> {
        let mut v = [0.0f32; 3];
        for slot in &mut v {
            let line = self.last_line();
            let Some(t) = self.next() else {
                return Err(self.expected("a number", None, line));
            };
            *slot = parse_number(t.text).map_err(|kind| self.err(t.line, kind))?;
        }
        Ok(Vec3::from(v))
    }

    /// `CHANNELS n name…` after the keyword.
    fn channel_list(&mut self) -> Result<Vec<Channel>, BvhError> {
        let line = self.last_line();
        let Some(count_token) = self.next() else {
            return Err(self.expected("a channel count", None, line));
        };
        let declared: usize = count_token.text.parse().map_err(|_| {
            self.err(
                count_token.line,
                BvhErrorKind::Expected {
                    expected: "a channel count (a whole number)".into(),
                    found: count_token.text.into(),
                },
            )
        })?;
        let mut channels = Vec::new();
        while channels.len() < declared {
            match self.peek() {
                Some(t) => match Channel::from_name(t.text) {
                    Some(c) => {
                        channels.push(c);
                        self.pos += 1;
                    }
                    None if is_keyword(t.text) => {
                        let found = channels.len();
                        return Err(self.err(
                            count_token.line,
                            BvhErrorKind::ChannelCount { declared, found },
                        ));
                    }
                    None => {
                        return Err(self.err(t.line, BvhErrorKind::UnknownChannel(t.text.into())));
                    }
                },
                None => {
                    let found = channels.len();
                    return Err(self.err(
                        count_token.line,
                        BvhErrorKind::ChannelCount { declared, found },
                    ));
                }
            }
        }
        Ok(channels)
    }

    fn next(&mut self) -> Option<Token<'a>> {
        let t = self.tokens.get(self.pos).copied();
        self.pos += usize::from(t.is_some());
        t
    }

    fn peek(&self) -> Option<Token<'a>> {
        self.tokens.get(self.pos).copied()
    }

    /// Line of the last token read (where a truncated file ends).
    fn last_line(&self) -> usize {
        self.tokens
            .get(
                self.pos
                    .saturating_sub(1)
                    .min(self.tokens.len().saturating_sub(1)),
            )
            .map_or(1, |t| t.line)
    }

    fn err(&self, line: usize, kind: BvhErrorKind) -> BvhError {
        BvhError::at(self.origin, line, kind)
    }

    fn expected(&self, what: &str, found: Option<Token<'_>>, fallback_line: usize) -> BvhError {
        let (line, found) = match found {
            Some(t) => (t.line, t.text.to_string()),
            None => (fallback_line, "end of file".to_string()),
        };
        self.err(
            line,
            BvhErrorKind::Expected {
                expected: what.into(),
                found,
            },
        )
    }
}

/// Words that end a CHANNELS list early.
fn is_keyword(word: &str) -> bool {
    ["JOINT", "END", "OFFSET", "CHANNELS", "ROOT", "}", "{"]
        .iter()
        .any(|k| word.eq_ignore_ascii_case(k))
}
