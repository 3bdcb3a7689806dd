//! Who may not use the workbench: a request without the token, a page of another origin.

use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::time::Duration;

use fantoccini::Client;
use serde_json::json;

use crate::page::until;

/// A WebSocket handshake by hand, as a page of `origin` (or a tool, without one) would send it: the status line.
pub fn handshake(url: &str, origin: Option<&str>, token: Option<&str>) -> Result<String, String> {
    let host = url
        .trim_start_matches("http://")
        .split('/')
        .next()
        .ok_or("no host")?
        .to_owned();
    let mut s = TcpStream::connect(&host).map_err(|e| e.to_string())?;
    s.set_read_timeout(Some(Duration::from_secs(5)))
        .map_err(|e| e.to_string())?;
    let path = token.map_or("/ws".to_owned(), |t| format!("/ws?token={t}"));
    let origin = origin.map(|o| format!("Origin: {o}\r\n")).unwrap_or_default();
    write!(
        s,
        "GET {path} HTTP/1.1\r\nHost: {host}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\
         Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n{origin}\r\n"
    )
    .map_err(|e| e.to_string())?;
    let mut buf = [0u8; 256];
    let n = s.read(&mut buf).map_err(|e| e.to_string())?;
    Ok(String::from_utf8_lossy(&buf[..n])
        .lines()
        .next()
        .unwrap_or("")
        .to_owned())
}

/// A page of another origin (this port, not the workbench's) that tries the workbench's WebSocket with the
/// right token and writes what happened into its title.
pub fn hostile_page(ws_url: String) -> Result<String, String> {
    let listener = TcpListener::bind("127.0.0.1:0").map_err(|e| e.to_string())?;
    let port = listener.local_addr().map_err(|e| e.to_string())?.port();
    let page = format!(
        "<!doctype html><title>trying</title><script>\
         const ws = new WebSocket({ws_url:?});\
         ws.onopen = () => {{ document.title = 'opened'; }};\
         ws.onerror = () => {{ document.title = 'refused'; }};\
         </script>"
    );
    std::thread::spawn(move || {
        for stream in listener.incoming().flatten().take(4) {
            let mut stream = stream;
            let mut buf = [0u8; 2048];
            let _ = stream.read(&mut buf);
            let _ = write!(
                stream,
                "HTTP/1.1 200 OK\r\nContent-Type: text/html\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{page}",
                page.len()
            );
        }
    });
    Ok(format!("http://127.0.0.1:{port}/"))
}

pub async fn other_origin(c: &Client, url: &str) -> Result<String, String> {
    let token = url.split("token=").nth(1).ok_or("no token in the URL")?;
    let ws = url.replace("http://", "ws://").replace("/?token=", "/ws?token=");
    let host = url.trim_start_matches("http://").split('/').next().unwrap_or("");
    // The workbench's own origin is let in, so the refusals below are the origin's and the token's.
    let own = handshake(url, Some(&format!("http://{host}")), Some(token))?;
    if !own.contains("101") {
        return Err(format!("the workbench's own origin was refused: {own}"));
    }
    let no_token = handshake(url, Some(&format!("http://{host}")), None)?;
    let wrong = handshake(url, None, Some("0123"))?;
    if !no_token.contains("403") || !wrong.contains("403") {
        return Err(format!("without the token: {no_token}; wrong token: {wrong}"));
    }
    let page = hostile_page(ws)?;
    c.goto(&page).await.map_err(|e| e.to_string())?;
    let title = until(
        c,
        "document.title !== 'trying' && document.title",
        Duration::from_secs(10),
    )
    .await?;
    if title != json!("refused") {
        return Err(format!("a page of another origin opened the WebSocket: {title}"));
    }
    Ok(format!(
        "own origin {own}; no token {no_token}; wrong token {wrong}; {page}: {title}"
    ))
}
