//! `mprog mcp`'s request handling: arbitrary bytes as the client's JSON-RPC lines after
//! the handshake (`mprog::mcp::fuzz_one`). The server must answer a final ping and stop
//! when the client hangs up: no panic, no hang, whatever came before.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(e) = mprog::mcp::fuzz_one(data) {
        panic!("{e}");
    }
});
