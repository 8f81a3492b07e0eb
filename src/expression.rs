//! Limits on the column expressions people write (`fit`'s input maps,
//! `replay --velocity-map`): checked before an expression is parsed, so
//! that a pasted mistake is a clear message instead of minutes in the
//! parser.

/// Longest expression accepted, characters.
pub const MAX_EXPRESSION_CHARS: usize = 1000;
/// Deepest nesting accepted: parentheses, and unary operators in a row.
pub const MAX_EXPRESSION_DEPTH: usize = 32;

/// Refuse an expression too long or too deeply nested to be a formula a
/// person wrote (and that would take the parser ages: a chain of 100 000
/// unary minus signs), before it is parsed.
pub fn check_size(text: &str) -> Result<(), String> {
    let n = text.chars().count();
    if n > MAX_EXPRESSION_CHARS {
        return Err(format!(
            "{n} characters: an expression may have at most {MAX_EXPRESSION_CHARS}"
        ));
    }
    let (mut depth, mut deepest, mut unary, mut longest) = (0usize, 0usize, 0usize, 0usize);
    let mut prev_operand = false;
    for c in text.chars() {
        match c {
            '(' => {
                depth += 1;
                deepest = deepest.max(depth);
                prev_operand = false;
                unary = 0;
            }
            ')' => {
                depth = depth.saturating_sub(1);
                prev_operand = true;
            }
            '-' | '!' | '+' if !prev_operand => {
                unary += 1;
                longest = longest.max(unary);
            }
            c if c.is_whitespace() => {}
            c => {
                prev_operand = c.is_alphanumeric() || c == '_' || c == '.';
                unary = 0;
            }
        }
    }
    if deepest.max(longest) > MAX_EXPRESSION_DEPTH {
        return Err(format!(
            "nested {} deep: an expression may nest parentheses or unary operators at most {MAX_EXPRESSION_DEPTH} deep",
            deepest.max(longest)
        ));
    }
    Ok(())
}

/// A long expression cut for a message.
pub fn shorten(text: &str) -> String {
    if text.chars().count() <= 60 {
        text.to_string()
    } else {
        format!("{}…", text.chars().take(60).collect::<String>())
    }
}
