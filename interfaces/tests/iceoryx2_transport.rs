//! Every message type travels through real iceoryx2 shared memory unchanged, including the
//! 160 KiB `Plan` written in place into a loaned sample (never on the stack).

mod common;

use iceoryx2::prelude::*;
use wingman_interfaces::*;

fn round_trip<M: Message + std::fmt::Debug>(node: &Node<ipc::Service>, value: &M) {
    let name = format!(
        "{}-{}",
        service_name(&format!("layout-test-{}", std::process::id()), M::SERVICE).unwrap(),
        M::NAME
    );
    let service = node
        .service_builder(&name.as_str().try_into().unwrap())
        .publish_subscribe::<M>()
        .open_or_create()
        .unwrap();
    let publisher = service.publisher_builder().create().unwrap();
    let subscriber = service.subscriber_builder().create().unwrap();

    let mut sample = publisher.loan_uninit().unwrap();
    let slot = M::zeroed_in(sample.payload_mut());
    *slot = *value;
    // SAFETY: `zeroed_in` initialised the payload.
    let sample = unsafe { sample.assume_init() };
    sample.send().unwrap();

    let received = subscriber.receive().unwrap().expect("one sample");
    assert_eq!(
        received.payload().as_bytes(),
        value.as_bytes(),
        "{}",
        M::NAME
    );
    received.payload().validate().unwrap();
}

#[test]
fn every_message_crosses_shared_memory_unchanged() {
    let node = NodeBuilder::new().create::<ipc::Service>().unwrap();
    round_trip(&node, &common::tasking());
    round_trip(&node, &common::lead_state());
    round_trip(&node, &common::lead_route());
    round_trip(&node, &common::threat_moving());
    round_trip(&node, &common::track_fix());
    round_trip(&node, &common::ownship());
    round_trip(&node, &common::plan());
    round_trip(&node, &common::status());
}
