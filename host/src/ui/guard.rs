//! Who may use the workbench: the holder of the per-run token, from a page this server served.
//!
//! A web page of another site in the same browser can open a WebSocket to `127.0.0.1` too; browsers send its
//! `Origin`, so the WebSocket and the API refuse any origin but the workbench's own. A site that rebinds its
//! DNS name to this machine passes an origin check against the `Host` it sends, so the token (random, per run,
//! printed only on this machine) is needed as well, on every address. Clients that are not browsers send no
//! `Origin`; they still need the token.

use std::net::SocketAddr;

/// The per-run secret in the workbench's URL.
#[derive(Clone, PartialEq, Eq)]
pub struct Token(String);

impl Token {
    /// 128 random bits from the operating system, as hex; without a random source there is no token (and no
    /// workbench: a guessable token guards nothing).
    pub fn random() -> Result<Self, getrandom::Error> {
        let mut bytes = [0u8; 16];
        getrandom::fill(&mut bytes)?;
        Ok(Self(bytes.iter().map(|b| format!("{b:02x}")).collect()))
    }

    /// The token's text, for the URL.
    pub fn as_str(&self) -> &str {
        &self.0
    }

    /// Whether `given` is the token, compared in time independent of where they differ.
    pub fn matches(&self, given: Option<&str>) -> bool {
        let Some(given) = given else { return false };
        let (a, b) = (self.0.as_bytes(), given.as_bytes());
        a.len() == b.len() && a.iter().zip(b).fold(0u8, |acc, (x, y)| acc | (x ^ y)) == 0
    }
}

/// Why a request is refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refused {
    /// No token, or the wrong one.
    Token,
    /// A page of another origin.
    Origin,
    /// A `Host` this server is not (a name rebound to this machine), or none.
    Host,
}

impl std::fmt::Display for Refused {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Token => "open the URL `ringpod ui` printed: this one has no token or the wrong one",
            Self::Origin => "refused: the request comes from a page of another origin",
            Self::Host => "refused: the request names another host than this workbench",
        })
    }
}

/// Checks one request: its token, its `Host` (every HTTP/1.1 request has one), and the `Origin` a browser sends.
///
/// On a loopback address only the names of this machine are accepted as `Host` (`127.0.0.1`, `localhost`,
/// `[::1]` with the port), on every request, with an `Origin` or without: a rebinding site is kept out even if
/// its page got the token. On another address the `Host` is whatever name the user reached it by. An `Origin`,
/// when sent, must be `http://` and that `Host`.
pub fn check(
    listen: SocketAddr,
    token: &Token,
    given: Option<&str>,
    origin: Option<&str>,
    host: Option<&str>,
) -> Result<(), Refused> {
    if !token.matches(given) {
        return Err(Refused::Token);
    }
    let host_ok = |h: &str| {
        if !listen.ip().is_loopback() {
            return true;
        }
        let port = listen.port();
        [
            format!("127.0.0.1:{port}"),
            format!("localhost:{port}"),
            format!("[::1]:{port}"),
            listen.to_string(),
        ]
        .iter()
        .any(|ok| ok.eq_ignore_ascii_case(h))
    };
    let host = host.filter(|h| host_ok(h)).ok_or(Refused::Host)?;
    match origin {
        None => Ok(()),
        Some(origin) if origin.eq_ignore_ascii_case(&format!("http://{host}")) => Ok(()),
        Some(_) => Err(Refused::Origin),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn token() -> Token {
        Token("00112233445566778899aabbccddeeff".into())
    }

    const LOOP: &str = "127.0.0.1:8080";

    #[test]
    fn tokens_are_random_and_compared_whole() {
        let (a, b) = (Token::random().unwrap(), Token::random().unwrap());
        assert_eq!(a.as_str().len(), 32);
        assert!(a != b, "two runs, two tokens");
        let t = token();
        assert!(t.matches(Some("00112233445566778899aabbccddeeff")));
        for wrong in [
            "",
            "00112233445566778899aabbccddeef",
            "00112233445566778899aabbccddeeff0",
            "x",
        ] {
            assert!(!t.matches(Some(wrong)), "{wrong}");
        }
        assert!(!t.matches(None));
    }

    #[test]
    fn the_workbench_page_passes_and_other_sites_do_not() {
        let listen: SocketAddr = LOOP.parse().unwrap();
        let t = token();
        let ok = Some(t.as_str());
        let page = |origin: Option<&str>, host: Option<&str>| check(listen, &t, ok, origin, host);
        assert_eq!(page(Some("http://127.0.0.1:8080"), Some("127.0.0.1:8080")), Ok(()));
        assert_eq!(page(Some("http://localhost:8080"), Some("localhost:8080")), Ok(()));
        // A tool that is not a browser sends no Origin.
        assert_eq!(page(None, Some(LOOP)), Ok(()));
        // Another site in the same browser.
        assert_eq!(page(Some("http://evil.example"), Some(LOOP)), Err(Refused::Origin));
        assert_eq!(page(Some("https://127.0.0.1:8080"), Some(LOOP)), Err(Refused::Origin));
        assert_eq!(page(Some("http://127.0.0.1:9090"), Some(LOOP)), Err(Refused::Origin));
        assert_eq!(page(Some("null"), Some(LOOP)), Err(Refused::Origin));
        // A site whose name was rebound to this machine: its own origin and Host agree, but the Host is not ours;
        // the same without an Origin (a client that is not a browser, or one that omits it).
        assert_eq!(
            page(Some("http://rebound.example:8080"), Some("rebound.example:8080")),
            Err(Refused::Host)
        );
        assert_eq!(page(None, Some("rebound.example:8080")), Err(Refused::Host));
        assert_eq!(page(None, Some("127.0.0.1:9090")), Err(Refused::Host));
        assert_eq!(page(Some("http://127.0.0.1:8080"), None), Err(Refused::Host));
        assert_eq!(page(None, None), Err(Refused::Host));
        // The token first, whatever the origin.
        assert_eq!(
            check(listen, &t, Some("wrong"), Some("http://127.0.0.1:8080"), Some(LOOP)),
            Err(Refused::Token)
        );
        assert_eq!(check(listen, &t, None, None, None), Err(Refused::Token));
    }

    #[test]
    fn on_another_address_the_host_is_the_name_used_and_the_token_decides() {
        let listen: SocketAddr = "0.0.0.0:8080".parse().unwrap();
        let t = token();
        let host = Some("rig-pc.local:8080");
        assert_eq!(
            check(listen, &t, Some(t.as_str()), Some("http://rig-pc.local:8080"), host),
            Ok(())
        );
        assert_eq!(
            check(listen, &t, Some(t.as_str()), Some("http://evil.example"), host),
            Err(Refused::Origin)
        );
        assert_eq!(
            check(listen, &t, None, Some("http://rig-pc.local:8080"), host),
            Err(Refused::Token)
        );
    }
}
