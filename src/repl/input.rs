//! When is an input finished? A line continues while a bracket, brace or parenthesis is
//! open, or when it ends with an operator, a comma or `=` (the language's own rule for
//! where a newline does not end a statement). Strings and `#` comments are skipped.

/// Words that, at the end of a line, ask for more.
const TRAILING_WORDS: &[&str] = &["and", "or", "not"];

/// True when `text` cannot be complete yet: open brackets or a trailing operator.
pub fn needs_more(text: &str) -> bool {
    let mut depth: i64 = 0;
    let mut last_line_code = "";
    for line in text.lines() {
        let code = strip_comment(line);
        depth += bracket_balance(code);
        last_line_code = code;
    }
    if depth > 0 {
        return true;
    }
    if text.ends_with('\n') {
        // An empty line after an operator does not end the statement either, but a
        // trailing blank line typed deliberately is the way out of a broken input.
        return false;
    }
    ends_with_operator(last_line_code.trim_end())
}

/// The line up to a `#` that is not inside a string.
fn strip_comment(line: &str) -> &str {
    let mut in_string = false;
    let mut escaped = false;
    for (i, c) in line.char_indices() {
        match c {
            _ if escaped => escaped = false,
            '\\' if in_string => escaped = true,
            '"' => in_string = !in_string,
            '#' if !in_string => return &line[..i],
            _ => {}
        }
    }
    line
}

/// Opened minus closed brackets outside strings.
fn bracket_balance(code: &str) -> i64 {
    let mut in_string = false;
    let mut escaped = false;
    let mut depth = 0;
    for c in code.chars() {
        match c {
            _ if escaped => escaped = false,
            '\\' if in_string => escaped = true,
            '"' => in_string = !in_string,
            '(' | '[' | '{' if !in_string => depth += 1,
            ')' | ']' | '}' if !in_string => depth -= 1,
            _ => {}
        }
    }
    depth
}

fn ends_with_operator(code: &str) -> bool {
    if code.is_empty() {
        return false;
    }
    if code.ends_with("..") {
        return true;
    }
    if let Some(c) = code.chars().last()
        && matches!(c, '+' | '-' | '*' | '/' | '<' | '>' | '=' | ',' | '@')
    {
        return true;
    }
    let last_word: String = code
        .chars()
        .rev()
        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
        .collect::<Vec<_>>()
        .into_iter()
        .rev()
        .collect();
    let before = &code[..code.len() - last_word.len()];
    let standalone = before.is_empty()
        || before.ends_with(|c: char| !c.is_ascii_alphanumeric() && c != '_' && c != '.');
    standalone && TRAILING_WORDS.contains(&last_word.to_ascii_lowercase().as_str())
}

#[cfg(test)]
mod tests {
    use super::needs_more;

    #[test]
    fn open_brackets_continue() {
        assert!(needs_more("always {"));
        assert!(needs_more("always {\n  head.y > 1"));
        assert!(!needs_more("always {\n  head.y > 1\n}"));
        assert!(needs_more("dist(l_hand,"));
        assert!(needs_more("[1, 2,"));
    }

    #[test]
    fn trailing_operators_continue() {
        for s in [
            "head.y >",
            "a +",
            "x and",
            "x or",
            "p ==",
            "let a =",
            "during 1s..",
            "x <=",
        ] {
            assert!(needs_more(s), "{s}");
        }
        for s in [
            "head.y > 1",
            "head.y > 1 m",
            "band",
            "l_hand.x",
            "minimize speed(pelvis)",
        ] {
            assert!(!needs_more(s), "{s}");
        }
    }

    #[test]
    fn strings_and_comments_do_not_count() {
        assert!(!needs_more("prompt \"a { person\""));
        assert!(!needs_more("head.y > 1 # and {"));
        assert!(!needs_more(":gen \"walk (slowly\" 4"));
    }

    #[test]
    fn too_many_closers_are_left_to_the_parser() {
        assert!(!needs_more("head.y > 1 }"));
    }
}
