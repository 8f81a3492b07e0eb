//! CDR decoding of every message type the project reads or writes: an
//! error or a message that encodes back; never a panic or a huge allocation.
#![no_main]
use friction_node::msgs::{self, from_cdr, to_cdr};
use libfuzzer_sys::fuzz_target;

fn roundtrip<T: serde::de::DeserializeOwned + serde::Serialize>(b: &[u8]) {
    if let Ok(m) = from_cdr::<T>(b) {
        to_cdr(&m).expect("a decoded message encodes");
    }
}

fuzz_target!(|data: &[u8]| {
    if data.is_empty() {
        return;
    }
    let b = &data[1..];
    match data[0] % 11 {
        0 => roundtrip::<msgs::Float64>(b),
        1 => roundtrip::<msgs::TwistStamped>(b),
        2 => roundtrip::<msgs::JointState>(b),
        3 => roundtrip::<msgs::Temperature>(b),
        4 => roundtrip::<msgs::FrictionEstimate>(b),
        5 => roundtrip::<msgs::FrictionEstimateV1>(b),
        6 => roundtrip::<msgs::FilmProfile>(b),
        7 => roundtrip::<msgs::LoopStatistics>(b),
        8 => roundtrip::<msgs::Header>(b),
        9 => {
            let _ = msgs::decode_estimate(b, true);
        }
        _ => {
            let _ = msgs::decode_estimate(b, false);
        }
    }
});
