//! The accept loop and one thread per connection: read one request under a
//! deadline, answer it, close; over plain TCP or TLS.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use super::parse::{Progress, RequestParser};
use super::slots::{Occupancy, Slots, Ticket};
use super::tls::{ServerConfig as TlsConfig, Tls};
use super::{Limits, Request, Response, Scheme, Service};

/// How long a client may take to read a response before it is dropped.
const WRITE_TIMEOUT: Duration = Duration::from_secs(10);
/// After answering, how long (in all) the server reads what the client
/// still sends, and how much, so that closing does not reset the
/// connection before the client has read the response.
const DRAIN_TIME: Duration = Duration::from_millis(500);
const DRAIN_BYTES: usize = 64 * 1024;

/// A running server; stops (and joins its accept thread) on drop.
pub struct Server {
    addr: SocketAddr,
    stop: Arc<AtomicBool>,
    slots: Arc<Slots>,
    accept: Option<JoinHandle<()>>,
}

impl std::fmt::Debug for Server {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Server").field("addr", &self.addr).finish()
    }
}

impl Server {
    /// Binds `addr` and serves every request with `service`, each
    /// connection on its own thread, within `limits`.
    ///
    /// Fails if `addr` cannot be bound or a limit is zero.
    pub fn start(
        addr: SocketAddr,
        service: Arc<dyn Service>,
        limits: Limits,
    ) -> std::io::Result<Self> {
        Self::start_with(addr, service, limits, None)
    }

    /// As [`start`](Self::start), over HTTPS with `tls`: the same limits,
    /// the request deadline covering the TLS handshake too.
    // Without the feature `tls` no `Tls` can exist, so this is never called.
    #[cfg_attr(not(feature = "tls"), allow(unreachable_code))]
    pub fn start_tls(
        addr: SocketAddr,
        service: Arc<dyn Service>,
        limits: Limits,
        tls: &Tls,
    ) -> std::io::Result<Self> {
        Self::start_with(addr, service, limits, Some(tls.config()))
    }

    fn start_with(
        addr: SocketAddr,
        service: Arc<dyn Service>,
        limits: Limits,
        tls: Option<TlsConfig>,
    ) -> std::io::Result<Self> {
        if limits.open_slots == 0 || limits.trusted_slots == 0 || limits.request_deadline.is_zero()
        {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "every server limit must be positive",
            ));
        }
        let listener = TcpListener::bind(addr)?;
        let addr = listener.local_addr()?;
        let stop = Arc::new(AtomicBool::new(false));
        let slots = Slots::new(limits.open_slots, limits.trusted_slots);
        let (stop_flag, pools) = (stop.clone(), slots.clone());
        let accept = std::thread::Builder::new()
            .name("hil-web-accept".into())
            .spawn(move || {
                for conn in listener.incoming() {
                    if stop_flag.load(Ordering::SeqCst) {
                        break;
                    }
                    let Ok(stream) = conn else { continue };
                    // The deadline counts from here, not from the first byte.
                    let deadline = Instant::now() + limits.request_deadline;
                    let Some(ticket) = pools.admit(&stream) else {
                        refuse_busy(stream);
                        continue;
                    };
                    let service = service.clone();
                    let tls = tls.clone();
                    // If the thread cannot start, the closure (stream and
                    // ticket) is dropped: the connection closes, the slot
                    // is given back.
                    let _ = std::thread::Builder::new()
                        .name("hil-web-conn".into())
                        .spawn(move || {
                            let socket = Socket {
                                tcp: stream,
                                deadline,
                            };
                            let conn = match tls {
                                None => Conn::Plain(socket),
                                Some(config) => match Conn::tls(config, socket) {
                                    Some(conn) => conn,
                                    None => return,
                                },
                            };
                            serve(conn, ticket, service.as_ref())
                        });
                }
            })?;
        Ok(Self {
            addr,
            stop,
            slots,
            accept: Some(accept),
        })
    }

    /// The address the server listens on (with the port actually bound).
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// How many connections each pool holds now.
    pub fn occupancy(&self) -> Occupancy {
        self.slots.occupancy()
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        // Wake the accept loop so that it sees the flag.
        let mut wake = self.addr;
        if wake.ip().is_unspecified() {
            wake.set_ip(if wake.is_ipv4() {
                std::net::Ipv4Addr::LOCALHOST.into()
            } else {
                std::net::Ipv6Addr::LOCALHOST.into()
            });
        }
        let _ = TcpStream::connect_timeout(&wake, Duration::from_secs(1));
        if let Some(h) = self.accept.take() {
            let _ = h.join();
        }
    }
}

fn refuse_busy(mut stream: TcpStream) {
    let _ = stream.set_write_timeout(Some(Duration::from_secs(1)));
    let _ = write_response(&mut stream, &Response::text(503, "busy"));
}

/// A connection's socket: every read must end by `deadline` (set before
/// each read of the socket, so a TLS handshake that trickles in cannot
/// outlast it either).
struct Socket {
    tcp: TcpStream,
    deadline: Instant,
}

impl Read for Socket {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let left = self.deadline.saturating_duration_since(Instant::now());
        // A zero timeout would mean "none" to the socket.
        if left.is_zero() {
            return Err(std::io::ErrorKind::TimedOut.into());
        }
        self.tcp.set_read_timeout(Some(left))?;
        self.tcp.read(buf)
    }
}

impl Write for Socket {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.tcp.write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.tcp.flush()
    }
}

/// One client's connection, plain or TLS.
enum Conn {
    Plain(Socket),
    #[cfg(feature = "tls")]
    Tls(Box<rustls::StreamOwned<rustls::ServerConnection, Socket>>),
}

impl Conn {
    /// A TLS connection over `socket`, or `None` if rustls refuses one.
    #[cfg(feature = "tls")]
    fn tls(config: TlsConfig, socket: Socket) -> Option<Self> {
        let conn = rustls::ServerConnection::new(config).ok()?;
        Some(Self::Tls(Box::new(rustls::StreamOwned::new(conn, socket))))
    }

    #[cfg(not(feature = "tls"))]
    fn tls(config: TlsConfig, _socket: Socket) -> Option<Self> {
        match config {}
    }

    fn socket(&mut self) -> &mut Socket {
        match self {
            Self::Plain(s) => s,
            #[cfg(feature = "tls")]
            Self::Tls(t) => &mut t.sock,
        }
    }

    fn handshaking(&self) -> bool {
        match self {
            Self::Plain(_) => false,
            #[cfg(feature = "tls")]
            Self::Tls(t) => t.conn.is_handshaking(),
        }
    }

    fn scheme(&self) -> Scheme {
        match self {
            Self::Plain(_) => Scheme::Http,
            #[cfg(feature = "tls")]
            Self::Tls(_) => Scheme::Https,
        }
    }

    /// Ends the response: TLS's close_notify, then no more writing.
    fn finish(&mut self) {
        #[cfg(feature = "tls")]
        if let Self::Tls(t) = self {
            t.conn.send_close_notify();
            while t.conn.wants_write() {
                match t.conn.write_tls(&mut t.sock) {
                    Ok(n) if n > 0 => {}
                    _ => break,
                }
            }
        }
        let _ = self.flush();
        let _ = self.socket().tcp.shutdown(std::net::Shutdown::Write);
    }
}

impl Read for Conn {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        match self {
            Self::Plain(s) => s.read(buf),
            #[cfg(feature = "tls")]
            Self::Tls(t) => t.read(buf),
        }
    }
}

impl Write for Conn {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match self {
            Self::Plain(s) => s.write(buf),
            #[cfg(feature = "tls")]
            Self::Tls(t) => t.write(buf),
        }
    }

    fn flush(&mut self) -> std::io::Result<()> {
        match self {
            Self::Plain(s) => s.flush(),
            #[cfg(feature = "tls")]
            Self::Tls(t) => t.flush(),
        }
    }
}

fn serve(mut conn: Conn, mut ticket: Ticket, service: &dyn Service) {
    let _ = conn.socket().tcp.set_write_timeout(Some(WRITE_TIMEOUT));
    let response = match read_request(&mut conn, &mut ticket, service) {
        Ok(req) => {
            // A handler bug must not take the server down.
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| service.handle(&req)))
                .unwrap_or_else(|_| Response::text(500, "internal error"))
        }
        // Before the TLS handshake is done there is no channel to answer
        // on (and writing would go on with the handshake): just close.
        Err(Some(_)) if conn.handshaking() => return,
        Err(Some(r)) => r,
        Err(None) => return, // the client went away, or was evicted
    };
    // Writing TLS may read (a key update): give it time of its own.
    conn.socket().deadline = Instant::now() + WRITE_TIMEOUT;
    let _ = write_response(&mut conn, &response);
    conn.finish();
    drain(&mut conn.socket().tcp);
}

/// Reads what the client still sends, within [`DRAIN_TIME`] and
/// [`DRAIN_BYTES`] in all.
fn drain(stream: &mut TcpStream) {
    let until = Instant::now() + DRAIN_TIME;
    let mut sink = [0u8; 1024];
    let mut total = 0;
    while total < DRAIN_BYTES {
        let left = until.saturating_duration_since(Instant::now());
        if left.is_zero() || stream.set_read_timeout(Some(left)).is_err() {
            break;
        }
        match stream.read(&mut sink) {
            Ok(0) | Err(_) => break,
            Ok(n) => total += n,
        }
    }
}

/// Reads one request by the socket's deadline; moves the connection to
/// the trusted pool as soon as its request line shows that the client may
/// be served there. `Err(Some(response))` for a request to refuse,
/// `Err(None)` when the client vanished (or its TLS failed).
fn read_request(
    conn: &mut Conn,
    ticket: &mut Ticket,
    service: &dyn Service,
) -> Result<Request, Option<Response>> {
    let mut parser = RequestParser::default();
    let mut chunk = [0u8; 2048];
    let mut placed = false;
    loop {
        let progress = match conn.read(&mut chunk) {
            Ok(0) => return Err(parser.end_of_input().map(Response::from)),
            Ok(n) => parser.push(&chunk[..n]),
            Err(e) if is_timeout(&e) => return Err(Some(Response::text(408, "too slow"))),
            Err(_) => return Err(None),
        };
        if !placed && let Some(path) = parser.path() {
            placed = true;
            if service.trusted(path) && !ticket.promote() {
                return Err(Some(Response::text(503, "busy")));
            }
        }
        match progress {
            Ok(Progress::NeedMore) => {}
            Ok(Progress::Complete(mut req)) => {
                req.scheme = conn.scheme();
                return Ok(req);
            }
            Err(refusal) => return Err(Some(refusal.into())),
        }
    }
}

fn write_response(stream: &mut impl Write, r: &Response) -> std::io::Result<()> {
    let head = format!(
        "HTTP/1.1 {} {}\r\nContent-Type: {}\r\nContent-Length: {}\r\nConnection: close\r\n\
         Cache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\n\
         X-Frame-Options: DENY\r\nReferrer-Policy: no-referrer\r\n\
         Content-Security-Policy: default-src 'none'; script-src 'self'; style-src 'self'; \
         img-src 'self' data:; connect-src 'self'; base-uri 'none'; form-action 'none'; \
         frame-ancestors 'none'\r\n\r\n",
        r.status,
        super::reason(r.status),
        r.content_type,
        r.body.len()
    );
    stream.write_all(head.as_bytes())?;
    stream.write_all(&r.body)
}

fn is_timeout(e: &std::io::Error) -> bool {
    matches!(
        e.kind(),
        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
    )
}
