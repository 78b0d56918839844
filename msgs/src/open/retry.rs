//! Opening a service that another process may be creating: which of
//! iceoryx2's failures pass ([`Transient`]), and the bounded retry
//! ([`retry`]).
//!
//! iceoryx2 0.10's `open_or_create` tries to open, else to create, for at
//! most its own creation timeout (1 s by default), then gives up with the
//! last error it saw: `DoesNotExist` if another process held the creation
//! all that time (`IsBeingCreatedByAnotherInstance`), which a busy machine
//! makes likely. It also returns at once, without looping, on states seen
//! while another process is half-way through creating or removing the
//! service: `InsufficientPermissions` (the static configuration is not
//! readable yet), `ServiceInCorruptedState` (not fully written yet),
//! `InternalFailure`, `UnableToCreateServiceTag`. All of these pass; a
//! mismatch of the service's settings (types, limits, version) does not.

use iceoryx2::service::builder::event::{EventCreateError, EventOpenError, EventOpenOrCreateError};
use iceoryx2::service::builder::publish_subscribe::{
    PublishSubscribeCreateError as PsCreate, PublishSubscribeOpenError as PsOpen,
    PublishSubscribeOpenOrCreateError as PsOpenOrCreate,
};
use std::fmt::Debug;
use std::time::{Duration, Instant};

/// The first pause between two tries; later ones double, up to [`MAX_PAUSE`].
/// Short: two processes creating the same service at once usually sort it
/// out within a few milliseconds.
pub const FIRST_PAUSE: Duration = Duration::from_millis(2);
/// The longest pause between two tries: each try reads a few files, so
/// even hundreds of waiting nodes cost the machine little, and a service
/// that becomes ready is seen within this long.
pub const MAX_PAUSE: Duration = Duration::from_millis(50);

/// Whether an error of iceoryx2's open-or-create may go away by itself
/// (another process is creating or removing the service), so that trying
/// again makes sense.
pub trait Transient: Debug {
    /// `true` if a later try may succeed.
    fn transient(&self) -> bool;
}

impl Transient for PsOpenOrCreate {
    fn transient(&self) -> bool {
        match self {
            Self::PublishSubscribeOpenError(e) => e.transient(),
            Self::PublishSubscribeCreateError(e) => e.transient(),
            Self::SystemInFlux => true,
        }
    }
}

impl Transient for PsOpen {
    fn transient(&self) -> bool {
        match self {
            Self::Interrupt
            | Self::DoesNotExist
            | Self::InternalFailure
            | Self::InsufficientPermissions
            | Self::ServiceInCorruptedState
            | Self::HangsInCreation
            | Self::IsMarkedForDestruction
            | Self::UnableToCreateServiceTag => true,
            Self::IncompatibleTypes
            | Self::IncompatibleMessagingPattern
            | Self::IncompatibleAttributes
            | Self::DoesNotSupportRequestedMinBufferSize
            | Self::DoesNotSupportRequestedMinHistorySize
            | Self::DoesNotSupportRequestedMinSubscriberBorrowedSamples
            | Self::DoesNotSupportRequestedAmountOfPublishers
            | Self::DoesNotSupportRequestedAmountOfSubscribers
            | Self::DoesNotSupportRequestedAmountOfNodes
            | Self::IncompatibleOverflowBehavior
            | Self::ExceedsMaxNumberOfNodes
            | Self::VersionMismatch
            | Self::UnableToAcquireTypeDefinition
            | Self::InvalidTypeDefinition => false,
        }
    }
}

impl Transient for PsCreate {
    fn transient(&self) -> bool {
        match self {
            Self::Interrupt
            | Self::ServiceInCorruptedState
            | Self::AlreadyExists
            | Self::InsufficientPermissions
            | Self::InternalFailure
            | Self::IsBeingCreatedByAnotherInstance
            | Self::HangsInCreation
            | Self::UnableToCreateServiceTag
            | Self::ServiceConfigCouldNotBeCreated
            | Self::UnableToGenerateUniqueServiceId => true,
            Self::SubscriberBufferMustBeLargerThanHistorySize
            | Self::UnableToAcquireTypeDefinition
            | Self::InvalidTypeDefinition => false,
        }
    }
}

impl Transient for EventOpenOrCreateError {
    fn transient(&self) -> bool {
        match self {
            Self::EventOpenError(e) => e.transient(),
            Self::EventCreateError(e) => e.transient(),
            Self::SystemInFlux => true,
        }
    }
}

impl Transient for EventOpenError {
    fn transient(&self) -> bool {
        match self {
            Self::Interrupt
            | Self::DoesNotExist
            | Self::InsufficientPermissions
            | Self::ServiceInCorruptedState
            | Self::InternalFailure
            | Self::HangsInCreation
            | Self::IsMarkedForDestruction
            | Self::UnableToCreateServiceTag => true,
            Self::IncompatibleMessagingPattern
            | Self::IncompatibleAttributes
            | Self::IncompatibleDeadline
            | Self::IncompatibleNotifierCreatedEvent
            | Self::IncompatibleNotifierDroppedEvent
            | Self::IncompatibleNotifierDeadEvent
            | Self::DoesNotSupportRequestedAmountOfNotifiers
            | Self::DoesNotSupportRequestedAmountOfListeners
            | Self::DoesNotSupportRequestedMaxEventId
            | Self::DoesNotSupportRequestedAmountOfNodes
            | Self::ExceedsMaxNumberOfNodes
            | Self::VersionMismatch => false,
        }
    }
}

impl Transient for EventCreateError {
    fn transient(&self) -> bool {
        !matches!(self, Self::EventIdExceedsMaxSupportedValue)
    }
}

/// How a run of tries ended without the service.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Failed<E> {
    /// An error that does not pass by itself, at try `tries`.
    Refused {
        /// iceoryx2's error.
        error: E,
        /// Tries made.
        tries: u32,
    },
    /// Still failing transiently when the patience ran out.
    NotReady {
        /// iceoryx2's last error.
        last: E,
        /// Tries made.
        tries: u32,
        /// Time spent trying.
        waited: Duration,
    },
}

/// Calls `f` until it succeeds, fails for good, or `patience` (counted from
/// the first try) would run out before the next, sleeping between tries
/// from [`FIRST_PAUSE`], doubling up to [`MAX_PAUSE`].
pub fn retry<T, E: Transient>(
    patience: Duration,
    mut f: impl FnMut() -> Result<T, E>,
) -> Result<T, Failed<E>> {
    let start = Instant::now();
    let mut pause = FIRST_PAUSE;
    let mut tries = 0;
    loop {
        tries += 1;
        let error = match f() {
            Ok(x) => return Ok(x),
            Err(e) if !e.transient() => return Err(Failed::Refused { error: e, tries }),
            Err(e) => e,
        };
        let waited = start.elapsed();
        if waited + pause > patience {
            return Err(Failed::NotReady {
                last: error,
                tries,
                waited,
            });
        }
        std::thread::sleep(pause);
        pause = (pause * 2).min(MAX_PAUSE);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, PartialEq)]
    struct Flaky(bool);

    impl Transient for Flaky {
        fn transient(&self) -> bool {
            self.0
        }
    }

    #[test]
    fn a_transient_failure_is_retried_until_it_passes() {
        let mut left = 3;
        let r = retry(Duration::from_secs(5), || {
            left -= 1;
            if left > 0 { Err(Flaky(true)) } else { Ok(left) }
        });
        assert_eq!(r, Ok(0));
    }

    #[test]
    fn a_lasting_failure_is_not_retried() {
        let r: Result<(), _> = retry(Duration::from_secs(5), || Err(Flaky(false)));
        assert_eq!(
            r,
            Err(Failed::Refused {
                error: Flaky(false),
                tries: 1
            })
        );
    }

    #[test]
    fn retries_stop_within_the_patience_and_say_how_long_they_took() {
        let patience = Duration::from_millis(100);
        let start = Instant::now();
        let r: Result<(), _> = retry(patience, || Err(Flaky(true)));
        assert!(start.elapsed() <= patience + MAX_PAUSE);
        match r {
            Err(Failed::NotReady { tries, waited, .. }) => {
                assert!(tries > 2, "{tries} tries");
                assert!(waited <= patience, "{waited:?}");
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn a_service_being_created_elsewhere_is_worth_waiting_for_but_a_type_clash_is_not() {
        let busy =
            PsOpenOrCreate::PublishSubscribeCreateError(PsCreate::IsBeingCreatedByAnotherInstance);
        assert!(busy.transient());
        assert!(PsOpenOrCreate::PublishSubscribeOpenError(PsOpen::DoesNotExist).transient());
        assert!(!PsOpenOrCreate::PublishSubscribeOpenError(PsOpen::IncompatibleTypes).transient());
        let half_written =
            EventOpenOrCreateError::EventOpenError(EventOpenError::InsufficientPermissions);
        assert!(half_written.transient());
        let fewer = EventOpenError::DoesNotSupportRequestedAmountOfNotifiers;
        assert!(!EventOpenOrCreateError::EventOpenError(fewer).transient());
    }
}
