//! The column expressions people write (`fit`'s input maps, `replay
//! --velocity-map`): their limits, checked before an expression is parsed
//! (a pasted mistake is a clear message instead of minutes in the parser),
//! and their functions, written as in any formula (`sin(q)`, `sqrt(x)`):
//! [`FUNCTIONS`], which `evalexpr` names `math::sin` (that spelling works
//! too), plus its `min`, `max`, `floor`, `round`, `ceil` and `if`.

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

/// The functions of one argument an expression may call by their usual
/// names (`evalexpr`'s `math::NAME`).
pub const FUNCTIONS: &[&str] = &[
    "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "asinh", "acosh", "atanh",
    "exp", "ln", "log2", "log10", "sqrt", "cbrt", "abs",
];

/// `evalexpr`'s other functions that an expression may call.
const OTHER_FUNCTIONS: &[&str] = &["min", "max", "floor", "round", "ceil", "if"];

/// What an expression may call, for messages.
pub fn functions_list() -> String {
    format!(
        "{}, {} (also math::NAME, e.g. math::atan2(y, x), math::pow(x, 2))",
        FUNCTIONS.join(", "),
        OTHER_FUNCTIONS.join(", ")
    )
}

/// `text` with every call of a [`FUNCTIONS`] name written as `evalexpr`
/// spells it (`sin(q)` → `math::sin(q)`); `math::sin(q)` stays as it is.
pub fn with_functions(text: &str) -> String {
    let chars: Vec<char> = text.chars().collect();
    let ident = |c: char| c.is_alphanumeric() || c == '_';
    let mut out = String::with_capacity(text.len() + 16);
    let mut i = 0;
    while i < chars.len() {
        if !ident(chars[i]) {
            out.push(chars[i]);
            i += 1;
            continue;
        }
        let start = i;
        while i < chars.len() && (ident(chars[i]) || chars[i] == ':') {
            i += 1;
        }
        let word: String = chars[start..i].iter().collect();
        let mut j = i;
        while j < chars.len() && chars[j].is_whitespace() {
            j += 1;
        }
        let called = j < chars.len() && chars[j] == '(';
        let number = chars[start].is_ascii_digit();
        if called && !number && FUNCTIONS.contains(&word.as_str()) {
            out.push_str("math::");
        }
        out.push_str(&word);
    }
    out
}

/// Refuse a call of a function an expression may not use, naming it and
/// what may be called.
pub fn check_functions<N: evalexpr::EvalexprNumericTypes>(
    node: &evalexpr::Node<N>,
) -> Result<(), String> {
    for f in node.iter_function_identifiers() {
        let known = OTHER_FUNCTIONS.contains(&f)
            || f.strip_prefix("math::").is_some_and(|m| {
                FUNCTIONS.contains(&m)
                    || [
                        "log",
                        "exp2",
                        "pow",
                        "atan2",
                        "hypot",
                        "is_nan",
                        "is_finite",
                    ]
                    .contains(&m)
            });
        if !known {
            return Err(format!(
                "`{f}(…)` is not a function an expression may call: {}",
                functions_list()
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn usual_function_names_are_called_as_evalexpr_spells_them() {
        assert_eq!(with_functions("sin(q) * 2"), "math::sin(q) * 2");
        assert_eq!(with_functions("math::sin(q)"), "math::sin(q)");
        assert_eq!(
            with_functions("sqrt (x_sq) + abs(-y) + tanh(v/0.1)"),
            "math::sqrt (x_sq) + math::abs(-y) + math::tanh(v/0.1)"
        );
        // A column that happens to be named like a function is no call.
        assert_eq!(with_functions("exp + cos_phi"), "exp + cos_phi");
        let node = evalexpr::build_operator_tree::<evalexpr::DefaultNumericTypes>(&with_functions(
            "sin(x) + max(x, 1)",
        ))
        .unwrap();
        assert!(check_functions(&node).is_ok());
        let bad =
            evalexpr::build_operator_tree::<evalexpr::DefaultNumericTypes>("sine(x)").unwrap();
        let e = check_functions(&bad).unwrap_err();
        assert!(e.contains("`sine(…)`") && e.contains("sin, cos"), "{e}");
    }
}
