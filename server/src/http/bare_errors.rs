//! The errors hyper answers itself, as the contract's JSON. A request line of 64 KiB or more
//! cannot be parsed into a URI, and headers beyond what hyper reads at all are refused before
//! any route or middleware sees the request; hyper then writes a bare status with no body
//! (`414 URI Too Long`, `431 Request Header Fields Too Large`, `content-length: 0`) and closes the
//! connection. This stream sits between hyper and the socket and writes, in place of exactly
//! such an answer, the same status with the JSON body every other error has.

use std::io;
use std::pin::Pin;
use std::task::{Context, Poll};

use tokio::io::{AsyncRead, AsyncWrite, ReadBuf};

/// A connection whose bare 414/431 answers from hyper are rewritten as JSON errors.
pub struct JsonBareErrors<S> {
    inner: S,
    /// The replacement being written: its bytes, how many are written, and the length of the
    /// answer it replaces (reported to hyper as written once the replacement is).
    replacing: Option<(Vec<u8>, usize, usize)>,
}

impl<S> JsonBareErrors<S> {
    /// Wrap a connection.
    pub fn new(inner: S) -> Self {
        JsonBareErrors { inner, replacing: None }
    }
}

/// The JSON answer that replaces hyper's bare answer `head`, if it is one of those we replace.
fn replacement(head: &[u8]) -> Option<Vec<u8>> {
    let (status, code, message) = if head.starts_with(b"HTTP/1.1 414 URI Too Long\r\n") {
        (
            "414 URI Too Long",
            "uri_too_long",
            format!("the request target is 65535 bytes or more; at most {}", super::MAX_URI_BYTES),
        )
    } else if head.starts_with(b"HTTP/1.1 431 Request Header Fields Too Large\r\n") {
        (
            "431 Request Header Fields Too Large",
            "headers_too_large",
            format!(
                "the request headers are larger than the server reads; at most {} headers and {} bytes",
                super::MAX_HEADERS,
                super::MAX_HEADER_BYTES
            ),
        )
    } else {
        return None;
    };
    // Only hyper's own answer, which has no body: ours (with a JSON body) pass unchanged.
    let end = head.windows(4).position(|w| w == b"\r\n\r\n")?;
    let lower = String::from_utf8_lossy(&head[..end]).to_ascii_lowercase();
    if !lower.contains("\r\ncontent-length: 0") || head.len() != end + 4 {
        return None;
    }
    let body = serde_json::json!({ "error": code, "message": message }).to_string();
    Some(
        format!(
            "HTTP/1.1 {status}\r\ncontent-type: application/json\r\ncache-control: no-store\r\n\
             connection: close\r\ncontent-length: {}\r\n\r\n{body}",
            body.len()
        )
        .into_bytes(),
    )
}

impl<S: AsyncRead + Unpin> AsyncRead for JsonBareErrors<S> {
    fn poll_read(mut self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &mut ReadBuf<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.inner).poll_read(cx, buf)
    }
}

impl<S: AsyncWrite + Unpin> AsyncWrite for JsonBareErrors<S> {
    fn poll_write(mut self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &[u8]) -> Poll<io::Result<usize>> {
        let this = &mut *self;
        if this.replacing.is_none() {
            match replacement(buf) {
                Some(bytes) => this.replacing = Some((bytes, 0, buf.len())),
                None => return Pin::new(&mut this.inner).poll_write(cx, buf),
            }
        }
        let Some((bytes, written, replaced)) = &mut this.replacing else { unreachable!("set above") };
        while *written < bytes.len() {
            match Pin::new(&mut this.inner).poll_write(cx, &bytes[*written..]) {
                Poll::Ready(Ok(0)) => return Poll::Ready(Err(io::ErrorKind::WriteZero.into())),
                Poll::Ready(Ok(n)) => *written += n,
                Poll::Ready(Err(e)) => return Poll::Ready(Err(e)),
                Poll::Pending => return Poll::Pending,
            }
        }
        let done = *replaced;
        this.replacing = None;
        Poll::Ready(Ok(done))
    }

    fn poll_flush(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.inner).poll_flush(cx)
    }

    fn poll_shutdown(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.inner).poll_shutdown(cx)
    }

    /// Vectored, as the socket is: hyper then writes an answer's head and body from their own
    /// buffers (`writev`), not copied into one (an 85 KB tile copied per answer cost about a
    /// fifth of the hot-tile throughput: issue 71). hyper's bare answers have no body, so such an
    /// answer is a write whose one non-empty buffer is the whole head, and is replaced as above.
    fn poll_write_vectored(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        bufs: &[io::IoSlice<'_>],
    ) -> Poll<io::Result<usize>> {
        let mut filled = bufs.iter().filter(|b| !b.is_empty());
        if let (Some(only), None) = (filled.next(), filled.next()) {
            if self.replacing.is_some() || replacement(only).is_some() {
                return self.poll_write(cx, only);
            }
        }
        Pin::new(&mut self.inner).poll_write_vectored(cx, bufs)
    }

    fn is_write_vectored(&self) -> bool {
        self.inner.is_write_vectored()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_bare_answers_are_replaced() {
        let bare = b"HTTP/1.1 414 URI Too Long\r\nconnection: close\r\ncontent-length: 0\r\ndate: x\r\n\r\n";
        let json = String::from_utf8(replacement(bare).unwrap()).unwrap();
        assert!(json.starts_with("HTTP/1.1 414 URI Too Long\r\n") && json.contains("\"uri_too_long\""), "{json}");
        let body = json.split("\r\n\r\n").nth(1).unwrap();
        assert!(json.contains(&format!("content-length: {}\r\n", body.len())));
        let bare = b"HTTP/1.1 431 Request Header Fields Too Large\r\ncontent-length: 0\r\n\r\n";
        assert!(String::from_utf8(replacement(bare).unwrap()).unwrap().contains("\"headers_too_large\""));
        // Our own JSON 414 and anything else pass.
        let ours = b"HTTP/1.1 414 URI Too Long\r\ncontent-length: 60\r\n\r\n{\"error\":\"uri_too_long\"}";
        assert!(replacement(ours).is_none());
        assert!(replacement(b"HTTP/1.1 200 OK\r\ncontent-length: 0\r\n\r\n").is_none());
        assert!(replacement(b"\x89PNG HTTP/1.1 414 URI Too Long\r\ncontent-length: 0\r\n\r\n").is_none());
    }
}
