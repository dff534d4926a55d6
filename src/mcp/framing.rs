//! The stdio framing between the client and the protocol engine: one JSON-RPC message per
//! line, each line bounded. A line that is not JSON, or not a JSON-RPC message, is answered
//! here with the JSON-RPC error the specification names (-32700 parse error, -32600 invalid
//! request) instead of being dropped, and the session goes on; a line past the bound is
//! skipped to its end without being held. Valid lines pass to the engine through an
//! in-memory pipe, and everything written to stdout (the engine's messages and these
//! errors) goes out whole lines at a time, so the two never interleave.

use tokio::io::{AsyncBufRead, AsyncBufReadExt, AsyncWrite, AsyncWriteExt, DuplexStream};
use tokio::sync::mpsc;

/// The longest message the server reads (a request is a few hundred bytes; this leaves room
/// for any argument a tool takes).
pub const MAX_LINE: usize = 4 << 20;

/// One line from the client: its bytes, or how long it ran past `MAX_LINE`.
enum Line {
    Text(Vec<u8>),
    TooLong(usize),
}

/// Reads up to the next `\n` (or end of input), keeping at most `MAX_LINE` bytes.
async fn next_line(input: &mut (impl AsyncBufRead + Unpin)) -> std::io::Result<Option<Line>> {
    let mut line = Vec::new();
    let mut length = 0usize;
    loop {
        let buf = input.fill_buf().await?;
        if buf.is_empty() {
            return Ok(match (length, length > MAX_LINE) {
                (0, _) => None,
                (n, true) => Some(Line::TooLong(n)),
                _ => Some(Line::Text(line)),
            });
        }
        let (chunk, done) = match buf.iter().position(|&b| b == b'\n') {
            Some(i) => (&buf[..i], Some(i + 1)),
            None => (buf, None),
        };
        length = length.saturating_add(chunk.len());
        if length <= MAX_LINE {
            line.extend_from_slice(chunk);
        } else {
            line = Vec::new();
        }
        let used = done.unwrap_or(buf.len());
        input.consume(used);
        if done.is_some() {
            return Ok(Some(if length > MAX_LINE {
                Line::TooLong(length)
            } else {
                Line::Text(line)
            }));
        }
    }
}

/// A JSON-RPC error answering the message `id`.
fn error_reply(id: serde_json::Value, code: i64, message: impl Into<String>) -> serde_json::Value {
    serde_json::json!({
        "jsonrpc": "2.0",
        "id": id,
        "error": {"code": code, "message": message.into()},
    })
}

/// A line as a JSON-RPC message (`None` for a blank line), or, for a line that cannot be handed
/// to the engine, the JSON-RPC error that answers it.
fn parse(line: &[u8]) -> Result<Option<serde_json::Value>, serde_json::Value> {
    let error =
        |id: serde_json::Value, code: i64, message: String| Err(error_reply(id, code, message));
    if line.iter().all(u8::is_ascii_whitespace) {
        return Ok(None);
    }
    let value: serde_json::Value = match serde_json::from_slice(line) {
        Ok(v) => v,
        Err(e) => return error(serde_json::Value::Null, -32700, format!("parse error: {e}")),
    };
    let Some(object) = value.as_object() else {
        return error(
            serde_json::Value::Null,
            -32600,
            "invalid request: a message is a JSON object".to_owned(),
        );
    };
    let id = object.get("id").cloned().unwrap_or_default();
    if object.get("jsonrpc").and_then(|v| v.as_str()) != Some("2.0") {
        return error(
            id,
            -32600,
            "invalid request: \"jsonrpc\" must be \"2.0\"".to_owned(),
        );
    }
    let is_request = object
        .get("method")
        .is_some_and(serde_json::Value::is_string);
    let is_response = object.contains_key("result") || object.contains_key("error");
    if !is_request && !is_response {
        return error(
            id,
            -32600,
            "invalid request: no \"method\" (or \"result\"/\"error\" in a response)".to_owned(),
        );
    }
    if let Some(id) = object.get("id")
        && !(id.is_string() || id.is_i64() || id.is_u64() || id.is_null())
    {
        return error(
            serde_json::Value::Null,
            -32600,
            "invalid request: \"id\" must be a string or an integer".to_owned(),
        );
    }
    Ok(Some(value))
}

/// What becomes of a line.
#[derive(Debug, PartialEq)]
enum Gate {
    Forward,
    Reply(serde_json::Value),
    Drop,
}

/// Holds the session to its protocol before the engine sees a message: until `initialize`
/// (which the engine must see first, or it stops the session), a request is answered
/// "not initialized" (a `ping` is answered, as the protocol allows), and a notification or
/// a response is dropped; afterwards, a `tools/call` whose params are not a tool name with
/// object arguments gets the invalid-params error instead of the engine's "method not found".
fn gate(value: &serde_json::Value, initialized: &mut bool) -> Gate {
    let method = value.get("method").and_then(serde_json::Value::as_str);
    let id = value.get("id").cloned();
    let reply = |id, code, message: &str| Gate::Reply(error_reply(id, code, message));
    if !*initialized {
        return match (method, id) {
            (Some("initialize"), Some(_)) => {
                *initialized = true;
                Gate::Forward
            }
            (Some("ping"), Some(id)) => Gate::Reply(serde_json::json!({
                "jsonrpc": "2.0",
                "id": id,
                "result": {},
            })),
            (Some(_), Some(id)) => reply(
                id,
                -32002,
                "the session is not initialized: send \"initialize\" first",
            ),
            _ => Gate::Drop,
        };
    }
    if method == Some("tools/call")
        && let Some(id) = id
    {
        let params = value.get("params");
        let named = params
            .and_then(|p| p.get("name"))
            .is_some_and(serde_json::Value::is_string);
        let arguments = params.and_then(|p| p.get("arguments"));
        if !named || arguments.is_some_and(|a| !a.is_object() && !a.is_null()) {
            return reply(
                id,
                -32602,
                "invalid params: tools/call takes {\"name\": a tool's name, \"arguments\": an object}",
            );
        }
    }
    Gate::Forward
}

/// Copies the client's lines to `engine`, answering bad ones through `out`; ends (closing
/// the engine's input) when the client closes its end.
pub async fn read_client(
    mut input: impl AsyncBufRead + Unpin,
    mut engine: DuplexStream,
    out: mpsc::Sender<Vec<u8>>,
) -> std::io::Result<()> {
    let mut initialized = false;
    while let Some(line) = next_line(&mut input).await? {
        let gated = match &line {
            Line::TooLong(n) => Gate::Reply(error_reply(
                serde_json::Value::Null,
                -32600,
                format!(
                    "invalid request: a message of {n} bytes is over the {MAX_LINE}-byte limit"
                ),
            )),
            Line::Text(text) => match parse(text) {
                Ok(Some(message)) => gate(&message, &mut initialized),
                Ok(None) => Gate::Forward,
                Err(error) => Gate::Reply(error),
            },
        };
        match (gated, line) {
            (Gate::Reply(error), _) => {
                let mut text = error.to_string().into_bytes();
                text.push(b'\n');
                if out.send(text).await.is_err() {
                    break;
                }
            }
            (Gate::Forward, Line::Text(mut text)) => {
                text.push(b'\n');
                engine.write_all(&text).await?;
            }
            (Gate::Forward | Gate::Drop, _) => {}
        }
    }
    engine.shutdown().await
}

/// Splits what the engine writes into lines for `out`.
pub async fn read_engine(engine: DuplexStream, out: mpsc::Sender<Vec<u8>>) -> std::io::Result<()> {
    let mut lines = tokio::io::BufReader::new(engine);
    loop {
        let mut line = Vec::new();
        if lines.read_until(b'\n', &mut line).await? == 0 {
            return Ok(());
        }
        if out.send(line).await.is_err() {
            return Ok(());
        }
    }
}

/// Writes whole lines to `output` as they come.
pub async fn write_lines(
    mut output: impl AsyncWrite + Unpin,
    mut lines: mpsc::Receiver<Vec<u8>>,
) -> std::io::Result<()> {
    while let Some(line) = lines.recv().await {
        output.write_all(&line).await?;
        output.flush().await?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nothing_reaches_the_engine_before_initialize_and_tool_calls_are_shaped() {
        let mut started = false;
        let mut at = |line: &str| gate(&serde_json::from_str(line).unwrap(), &mut started);
        let code = |g: Gate| match g {
            Gate::Reply(v) => v["error"]["code"].as_i64(),
            _ => None,
        };
        assert_eq!(
            code(at(r#"{"jsonrpc":"2.0","id":1,"method":"tools/list"}"#)),
            Some(-32002)
        );
        assert_eq!(
            at(r#"{"jsonrpc":"2.0","method":"notifications/initialized"}"#),
            Gate::Drop
        );
        assert_eq!(at(r#"{"jsonrpc":"2.0","id":5,"result":{}}"#), Gate::Drop);
        assert_eq!(
            at(r#"{"jsonrpc":"2.0","id":2,"method":"ping"}"#),
            Gate::Reply(serde_json::json!({"jsonrpc": "2.0", "id": 2, "result": {}}))
        );
        assert_eq!(
            at(r#"{"jsonrpc":"2.0","id":3,"method":"initialize","params":{}}"#),
            Gate::Forward
        );
        assert_eq!(
            at(r#"{"jsonrpc":"2.0","method":"notifications/initialized"}"#),
            Gate::Forward
        );
        for bad in [
            r#"{"jsonrpc":"2.0","id":4,"method":"tools/call"}"#,
            r#"{"jsonrpc":"2.0","id":4,"method":"tools/call","params":{"name":"info","arguments":"str"}}"#,
            r#"{"jsonrpc":"2.0","id":4,"method":"tools/call","params":{"arguments":{}}}"#,
        ] {
            assert_eq!(code(at(bad)), Some(-32602), "{bad}");
        }
        assert_eq!(
            at(
                r#"{"jsonrpc":"2.0","id":4,"method":"tools/call","params":{"name":"info","arguments":{}}}"#
            ),
            Gate::Forward
        );
    }

    #[test]
    fn bad_lines_get_the_errors_json_rpc_names() {
        let code = |line: &str| {
            parse(line.as_bytes())
                .err()
                .map(|e| e["error"]["code"].clone())
        };
        assert_eq!(code("this is not json"), Some((-32700).into()));
        assert_eq!(code("[1, 2]"), Some((-32600).into()));
        assert_eq!(
            code(r#"{"jsonrpc":"1.0","id":1,"method":"x"}"#),
            Some((-32600).into())
        );
        assert_eq!(code(r#"{"jsonrpc":"2.0","id":1}"#), Some((-32600).into()));
        assert_eq!(
            code(r#"{"jsonrpc":"2.0","id":[1],"method":"x"}"#),
            Some((-32600).into())
        );
        assert_eq!(
            code(r#"{"jsonrpc":"2.0","id":1,"method":"tools/list"}"#),
            None
        );
        assert_eq!(code("   "), None);
        // The id of a request that is otherwise wrong is kept, so the client can match it.
        let e = parse(br#"{"jsonrpc":"2.0","id":7}"#)
            .err()
            .unwrap_or_default();
        assert_eq!(e["id"], 7);
    }

    #[tokio::test]
    async fn a_line_past_the_bound_is_skipped_and_the_next_read() {
        let mut input = vec![b'x'; MAX_LINE + 10];
        input.extend_from_slice(b"\n{\"a\":1}\n");
        let mut reader = tokio::io::BufReader::new(&input[..]);
        assert!(matches!(
            next_line(&mut reader).await,
            Ok(Some(Line::TooLong(n))) if n == MAX_LINE + 10
        ));
        assert!(matches!(
            next_line(&mut reader).await,
            Ok(Some(Line::Text(t))) if t == b"{\"a\":1}"
        ));
        assert!(matches!(next_line(&mut reader).await, Ok(None)));
    }
}
