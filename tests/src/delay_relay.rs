//! A TCP relay that holds every byte for a fixed time each way
//! ([`DelayRelay`]): the real delay of a link where the kernel has no
//! `netem` (`tc qdisc … netem` refused, as on VMs built without
//! `sch_netem`). It listens on an address of the root namespace's veth end
//! and forwards each connection to the host's daemon across the veth; what
//! it reads at `t` it writes at `t + delay`, in order, so the streams stay
//! TCP's (reliable, ordered) with `delay` added each way — what `netem
//! delay` does to the packets, above the socket instead of below it.

use std::io::{Read, Write};
use std::net::{Shutdown, SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// How often the accepting thread looks at the stop flag.
const POLL: Duration = Duration::from_millis(10);

/// Bytes read at once.
const CHUNK: usize = 64 * 1024;

/// The running relay; stopped (every connection shut) when dropped.
#[derive(Debug)]
pub struct DelayRelay {
    addr: SocketAddr,
    stop: Arc<AtomicBool>,
    streams: Arc<Mutex<Vec<TcpStream>>>,
    accept: Option<JoinHandle<()>>,
}

impl DelayRelay {
    /// Listens on `listen` (port 0: any) and relays each connection to
    /// `upstream`, `delay` each way.
    #[must_use]
    pub fn start(listen: SocketAddr, upstream: SocketAddr, delay: Duration) -> Self {
        let listener = TcpListener::bind(listen).expect("the relay's listening socket");
        listener.set_nonblocking(true).expect("non-blocking accept");
        let addr = listener.local_addr().expect("a bound address");
        let stop = Arc::new(AtomicBool::new(false));
        let streams = Arc::new(Mutex::new(Vec::new()));
        let (s, st) = (stop.clone(), streams.clone());
        let accept = std::thread::spawn(move || {
            while !s.load(Ordering::Relaxed) {
                match listener.accept() {
                    Ok((client, _)) => relay(client, upstream, delay, &st),
                    Err(_) => std::thread::sleep(POLL),
                }
            }
        });
        Self {
            addr,
            stop,
            streams,
            accept: Some(accept),
        }
    }

    /// Where it listens.
    #[must_use]
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }
}

impl Drop for DelayRelay {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.accept.take() {
            let _ = t.join();
        }
        for s in self.streams.lock().expect("the relay's streams").drain(..) {
            let _ = s.shutdown(Shutdown::Both);
        }
    }
}

/// Relays `client` to a new connection to `upstream`, both ways; the
/// streams are kept in `streams` to be shut at the end.
fn relay(
    client: TcpStream,
    upstream: SocketAddr,
    delay: Duration,
    streams: &Mutex<Vec<TcpStream>>,
) {
    let Ok(server) = TcpStream::connect(upstream) else {
        return;
    };
    let clone = |s: &TcpStream| s.try_clone().expect("a socket handle");
    let _ = client.set_nonblocking(false);
    for s in [&client, &server] {
        let _ = s.set_nodelay(true);
        streams.lock().expect("the relay's streams").push(clone(s));
    }
    pipe(clone(&client), clone(&server), delay);
    pipe(server, client, delay);
}

/// Copies `from` into `to`, each chunk `delay` after it was read: a reader
/// thread stamps the chunks, a writer thread writes each when it is due.
fn pipe(mut from: TcpStream, mut to: TcpStream, delay: Duration) {
    let (tx, rx) = mpsc::channel::<(Instant, Vec<u8>)>();
    std::thread::spawn(move || {
        let mut buf = vec![0; CHUNK];
        while let Ok(n @ 1..) = from.read(&mut buf) {
            if tx
                .send((Instant::now() + delay, buf[..n].to_vec()))
                .is_err()
            {
                break;
            }
        }
    });
    std::thread::spawn(move || {
        for (due, bytes) in rx {
            std::thread::sleep(due.saturating_duration_since(Instant::now()));
            if to.write_all(&bytes).is_err() {
                break;
            }
        }
        let _ = to.shutdown(Shutdown::Write);
    });
}
