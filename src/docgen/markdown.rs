//! Fenced code blocks of markdown text: what the book tests check. A block opens with
//! ```` ```lang,attr1,attr2 ```` (or spaces) and closes with ```` ``` ````.

/// One fenced block.
#[derive(Clone, Debug, PartialEq)]
pub struct CodeBlock {
    /// First word of the info string (`mprog`).
    pub lang: String,
    /// Remaining words (`error`, a diagnostic code, `repl`, …).
    pub attrs: Vec<String>,
    /// The block's text, each line ending in `\n`.
    pub text: String,
    /// 1-based line of the opening fence.
    pub line: usize,
}

/// Every fenced block in `md`, in order.
pub fn code_blocks(md: &str) -> Vec<CodeBlock> {
    let mut out = Vec::new();
    let mut open: Option<CodeBlock> = None;
    for (i, line) in md.lines().enumerate() {
        let trimmed = line.trim_start();
        match open.as_mut() {
            None => {
                if let Some(info) = trimmed.strip_prefix("```") {
                    let mut words = info
                        .split([',', ' '])
                        .filter(|w| !w.is_empty())
                        .map(str::to_string);
                    open = Some(CodeBlock {
                        lang: words.next().unwrap_or_default(),
                        attrs: words.collect(),
                        text: String::new(),
                        line: i + 1,
                    });
                }
            }
            Some(b) => {
                if trimmed.starts_with("```") {
                    out.extend(open.take());
                } else {
                    b.text.push_str(line);
                    b.text.push('\n');
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_with_attributes() {
        let md = "text\n```mprog\nhead.y > 1\n```\n\n```mprog,error mprog::unknown_joint\nx\n```\n```\nplain\n```\n";
        let b = code_blocks(md);
        assert_eq!(b.len(), 3);
        assert_eq!(
            (b[0].lang.as_str(), b[0].text.as_str(), b[0].line),
            ("mprog", "head.y > 1\n", 2)
        );
        assert_eq!(b[1].attrs, vec!["error", crate::lang::codes::UNKNOWN_JOINT]);
        assert_eq!(b[2].lang, "");
    }
}
