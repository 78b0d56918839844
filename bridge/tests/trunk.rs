//! A trunk between two Zenoh sessions on 127.0.0.1 (explicit endpoints,
//! scouting off): every state arrives once, in order, with its bytes; a
//! link whose receiver stalls holds back only itself; real time keeps the
//! newest; a bundle that is not states is named.

use bridge::remote::link::{Flow, LinkError, Window};
use bridge::remote::trunk::{BUNDLE_MOST, Direct, TrunkReceiver, TrunkSender};
use bridge::remote::zconfig;
use bridge::trust::Security;
use msgs::StateMsg;
use msgs::bytes::Bytes;
use std::time::{Duration, Instant};
use zenoh::Wait;

const WINDOW: Flow = Flow::Window(Window {
    window: 8,
    ack_every: 2,
});

/// Two sessions, the second dialling the first, and a key of their own.
fn pair() -> (zenoh::Session, zenoh::Session, String) {
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .expect("a free port")
        .port();
    let at = format!("tcp/127.0.0.1:{port}");
    let a = zconfig::open(std::slice::from_ref(&at), &[], &Security::Insecure).expect("a");
    let b = zconfig::open(&[], &[at], &Security::Insecure).expect("b");
    (a, b, format!("attsync/test-{port}/states/a/b"))
}

fn state(sender: u32, step: u64) -> StateMsg {
    let mut m = StateMsg::from_bytes(&[0u8; StateMsg::SIZE]).expect("size");
    m.version = msgs::PROTOCOL_VERSION;
    m.sender = sender;
    m.step = step;
    m.w = [step as f64, f64::from(sender), -1.5];
    m
}

fn ms(n: u64) -> Duration {
    Duration::from_millis(n)
}

/// A delivery that checks each state of `sender` comes in order.
fn check(sender: u32, got: &mut u64) -> impl FnOnce(Vec<u8>) -> Result<(), LinkError> + '_ {
    move |bytes| {
        assert_eq!(StateMsg::from_bytes(&bytes).unwrap(), state(sender, *got));
        *got += 1;
        Ok(())
    }
}

/// Waits up to 10 s for `ok`.
fn until(what: &str, mut ok: impl FnMut() -> bool) {
    let start = Instant::now();
    while !ok() {
        assert!(start.elapsed() < Duration::from_secs(10), "{what}");
        std::thread::sleep(Duration::from_millis(1));
    }
}

/// Sends the next states of every link, up to `per` each, as far as its
/// credit allows, in one bundle; whether anything was sent.
fn pump(tx: &mut TrunkSender, next: &mut [u64], per: u64) -> bool {
    let mut bundle = Vec::new();
    let mut counts = vec![0; next.len()];
    let most = (BUNDLE_MOST / next.len()) as u64;
    for (i, n) in next.iter_mut().enumerate() {
        let credit = tx.credit(i) as u64;
        let take = credit.min(per - *n).min(most);
        for _ in 0..take {
            bundle.extend_from_slice(&state(tx.senders()[i], *n).to_bytes());
            *n += 1;
        }
        counts[i] = take;
    }
    if !bundle.is_empty() {
        tx.send(bundle, &counts).expect("send");
    }
    !counts.iter().all(|&c| c == 0)
}

#[test]
fn every_state_arrives_once_in_order_and_a_stalled_link_holds_back_only_itself() {
    let (a, b, key) = pair();
    let senders = vec![3, 0, 7];
    let rx = TrunkReceiver::open(&b, &key, senders.clone(), WINDOW).expect("receiver");
    let mut tx = TrunkSender::open(&a, &key, senders.clone(), WINDOW).expect("sender");
    let inputs: Vec<_> = senders.iter().map(|&s| rx.input(s).unwrap()).collect();
    // an idle receiver repeats its hello (the first went before anyone listened)
    until("the hello", || {
        assert!(!inputs[0].take(ms(5), |_| Ok::<_, LinkError>(())).unwrap());
        tx.credit(0) > 0
    });
    let per = 200;
    let mut next = vec![0; 3];
    let mut got = vec![0u64; 3];
    // links 3 and 0 are read; link 7's reader stalls
    let start = Instant::now();
    while got[0] < per || got[1] < per {
        assert!(
            start.elapsed() < Duration::from_secs(20),
            "stuck at {got:?}"
        );
        pump(&mut tx, &mut next, per);
        for i in 0..2 {
            while inputs[i]
                .take(ms(1), check(senders[i], &mut got[i]))
                .unwrap()
            {}
        }
    }
    assert_eq!(next[2], 8, "the stalled link sent its window, no more");
    assert_eq!(tx.credit(2), 0);
    // link 7 resumes: the rest of its states follow, in order
    while got[2] < per {
        assert!(
            start.elapsed() < Duration::from_secs(40),
            "stuck at {got:?}"
        );
        pump(&mut tx, &mut next, per);
        inputs[2].take(ms(1), check(7, &mut got[2])).unwrap();
    }
    assert!(!inputs[2].take(ms(50), check(7, &mut got[2])).unwrap());
    until("every count acknowledged", || {
        (0..3).all(|i| tx.credit(i) >= 7)
    });
}

#[test]
fn in_real_time_an_inbox_keeps_the_newest_states() {
    let (a, b, key) = pair();
    let flow = Flow::Freshest { depth: 4 };
    let rx = TrunkReceiver::open(&b, &key, vec![5], flow).expect("receiver");
    let mut tx = TrunkSender::open(&a, &key, vec![5], flow).expect("sender");
    let input = rx.input(5).unwrap();
    until("the hello", || {
        assert!(!input.take(ms(5), |_| Ok::<_, LinkError>(())).unwrap());
        tx.credit(0) > 0
    });
    for n in 0..100 {
        tx.send(state(5, n).to_bytes(), &[1]).expect("send");
    }
    std::thread::sleep(Duration::from_secs(1)); // all arrive meanwhile
    let mut steps = Vec::new();
    until("the last state", || {
        let got = |b: Vec<u8>| {
            steps.push(StateMsg::from_bytes(&b).unwrap().step);
            Ok::<_, LinkError>(())
        };
        input.take(ms(5), got).unwrap();
        steps.last() == Some(&99)
    });
    assert_eq!(steps, [96, 97, 98, 99]);
}

#[test]
fn a_bundle_that_is_not_states_of_its_links_is_named() {
    for (bad, says) in [
        (vec![1u8; StateMsg::SIZE + 3], "a bundle of 155 bytes"),
        (state(9, 0).to_bytes(), "a state of sender Some(9)"),
    ] {
        let (a, b, key) = pair();
        let rx = TrunkReceiver::open(&b, &key, vec![5], WINDOW).expect("receiver");
        let publisher = a.declare_publisher(key.clone()).wait().expect("publisher");
        let input = rx.input(5).unwrap();
        let start = Instant::now();
        let err = loop {
            assert!(start.elapsed() < Duration::from_secs(10), "no error");
            publisher.put(bad.clone()).wait().expect("put");
            if let Err(e) = input.take(ms(20), |_| Ok::<_, LinkError>(())) {
                break e;
            }
        };
        assert!(err.to_string().contains(says), "{err}");
    }
}

/// Takes what the link's thread is not busy with, refusing every third.
struct Picky(std::sync::Arc<std::sync::Mutex<Vec<u64>>>);

impl Direct for Picky {
    fn try_now(&self, state: &[u8]) -> Result<bool, LinkError> {
        let step = (StateMsg::from_bytes(state))
            .map_err(|e| LinkError::Malformed(e.to_string()))?
            .step;
        if step % 3 == 0 {
            return Ok(false);
        }
        self.0.lock().unwrap().push(step);
        Ok(true)
    }

    fn wake(&self) {}
}

#[test]
fn states_delivered_from_the_callback_never_overtake_those_left_to_the_thread() {
    let (a, b, key) = pair();
    let rx = TrunkReceiver::open(&b, &key, vec![2], WINDOW).expect("receiver");
    let mut tx = TrunkSender::open(&a, &key, vec![2], WINDOW).expect("sender");
    let input = rx.input(2).unwrap();
    let seen = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    input.set_direct(std::sync::Arc::new(Picky(seen.clone())));
    until("the hello", || {
        assert!(!input.take(ms(5), |_| Ok::<_, LinkError>(())).unwrap());
        tx.credit(0) > 0
    });
    let per = 3000;
    let mut next = vec![0];
    let start = Instant::now();
    while seen.lock().unwrap().len() < per as usize {
        assert!(start.elapsed() < Duration::from_secs(30), "stuck");
        pump(&mut tx, &mut next, per);
        let slow = |b: Vec<u8>| {
            std::thread::sleep(Duration::from_micros(200)); // the thread holds back
            seen.lock()
                .unwrap()
                .push(StateMsg::from_bytes(&b).unwrap().step);
            Ok::<_, LinkError>(())
        };
        input.take(ms(1), slow).unwrap();
    }
    let seen = seen.lock().unwrap();
    assert_eq!(*seen, (0..per).collect::<Vec<_>>());
    until("every state acknowledged", || tx.credit(0) >= 7);
}
