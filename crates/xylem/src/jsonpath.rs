//! The field a serde_json error is about, found from its line and column in the text, since
//! serde_json names only the position ("invalid type: string, expected f32 at line 123 column
//! 24") and a reader of a 200-frame manifest wants `frames[3].intensity`.

/// One open container on the way to the error.
enum Open {
    /// An object, with the key whose value is being read (None between members).
    Object(Option<String>),
    /// An array, with the index of the element being read.
    Array(usize),
}

/// The path (`frames[3].intensity`) of the value at 1-based `line` and `column` of `text`
/// (columns count bytes, as serde_json's do); empty at the top level.
pub(crate) fn path_at(text: &str, line: usize, column: usize) -> String {
    let mut stack: Vec<Open> = Vec::new();
    let mut expect_key = false;
    let (mut l, mut c) = (1usize, 0usize);
    let mut chars = text.char_indices().peekable();
    while let Some((_, ch)) = chars.next() {
        if ch == '\n' {
            l += 1;
            c = 0;
        } else {
            c += ch.len_utf8();
        }
        // serde_json's column is the last byte it read (before a peeked `{` or `[`).
        if l > line || (l == line && c > column) {
            break;
        }
        match ch {
            '{' => {
                stack.push(Open::Object(None));
                expect_key = true;
            }
            '[' => stack.push(Open::Array(0)),
            '}' | ']' => {
                stack.pop();
            }
            ',' => match stack.last_mut() {
                Some(Open::Array(i)) => *i += 1,
                Some(Open::Object(k)) => {
                    *k = None;
                    expect_key = true;
                }
                None => {}
            },
            '"' => {
                let mut s = String::new();
                let mut escaped = false;
                for (_, ch) in chars.by_ref() {
                    c += ch.len_utf8();
                    if ch == '\n' {
                        l += 1;
                        c = 0;
                    }
                    match (escaped, ch) {
                        (false, '\\') => escaped = true,
                        (false, '"') => break,
                        _ => {
                            escaped = false;
                            s.push(ch);
                        }
                    }
                }
                if expect_key {
                    if let Some(Open::Object(k)) = stack.last_mut() {
                        *k = Some(s);
                    }
                    expect_key = false;
                }
            }
            _ => {}
        }
    }
    let mut path = String::new();
    for o in &stack {
        match o {
            Open::Object(Some(k)) => {
                if !path.is_empty() {
                    path.push('.');
                }
                path.push_str(k);
            }
            Open::Object(None) => {}
            Open::Array(i) => path.push_str(&format!("[{i}]")),
        }
    }
    path
}

/// serde_json's message with the field it is about: "field `frames[3].intensity`: invalid
/// type: …"; the message alone for syntax errors and errors at the top level.
pub fn describe(text: &str, e: &serde_json::Error) -> String {
    let field = match e.classify() {
        serde_json::error::Category::Data => path_at(text, e.line(), e.column()),
        _ => String::new(),
    };
    if field.is_empty() {
        e.to_string()
    } else {
        format!("field `{field}`: {e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_field_of_a_type_error() {
        let text = "{\n \"camera\": {\"width\": 4},\n \"frames\": [\n  {\"image\": \"a\\\"b\", \"intensity\": [1, 2, 3]},\n  {\"image\": \"c\", \"intensity\": \"bright\"}\n ]\n}";
        #[derive(serde::Deserialize, Debug)]
        #[allow(dead_code)]
        struct F {
            image: String,
            intensity: [f32; 3],
        }
        #[derive(serde::Deserialize, Debug)]
        #[allow(dead_code)]
        struct M {
            camera: serde_json::Value,
            frames: Vec<F>,
        }
        let e = serde_json::from_str::<M>(text).unwrap_err();
        let d = describe(text, &e);
        assert!(
            d.starts_with("field `frames[1].intensity`: invalid type"),
            "{d}"
        );
        // A syntax error keeps serde's message alone.
        let e = serde_json::from_str::<M>("{\"camera\": ").unwrap_err();
        assert!(!describe("{\"camera\": ", &e).contains("field"));
        // A map or an array in place of a number is blamed on that element.
        for bad in ["{}", "[]", "null", "\"x\""] {
            let text = format!("[1.0,{bad},2.0]");
            let e = serde_json::from_str::<[f32; 3]>(&text).unwrap_err();
            assert_eq!(path_at(&text, e.line(), e.column()), "[1]", "{bad}");
        }
    }
}
