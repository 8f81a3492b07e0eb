//! The `friction-node` command line: parse, dispatch (see `cli/`), and map
//! errors to exit codes.
//!
//! | exit code | meaning |
//! |---|---|
//! | 0 | success |
//! | 1 | the run went on but its recording failed (`run`) |
//! | 2 | bad arguments, configuration or input; an output that could not be written |
//! | 3 | `replay --expect-identical`: the re-simulation differs |
//! | 4 | `fit`: the fit did not converge (the best point found is written) |
//! | 5 | `replay --expect-identical`: the bag holds no recorded estimates to compare with |
//! | 130, 143 | stopped by SIGINT, SIGTERM (`simulate`, `study`, `replay`, `fit`): nothing half-written is left |
//!
//! | file | job |
//! |---|---|
//! | `main.rs` | the counting allocator, parsing, dispatch, exit codes |
//! | `cli/` | argument types and one file per group of subcommands |

mod cli;

use std::cell::Cell;

/// Counts heap allocations (per thread) so that `bench` can report
/// allocations per step.
struct CountingAlloc;

thread_local! {
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

fn count_allocation() {
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

unsafe impl std::alloc::GlobalAlloc for CountingAlloc {
    unsafe fn alloc(&self, layout: std::alloc::Layout) -> *mut u8 {
        count_allocation();
        unsafe { std::alloc::System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: std::alloc::Layout) {
        unsafe { std::alloc::System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: std::alloc::Layout, size: usize) -> *mut u8 {
        count_allocation();
        unsafe { std::alloc::System.realloc(ptr, layout, size) }
    }
}

#[global_allocator]
static GLOBAL: CountingAlloc = CountingAlloc;

/// Tune glibc's allocator for the command's life.
///
/// - **Long-running** (`run`, `soak`, `bench-latency`, `bench-recorder`):
///   large allocations (MCAP chunk buffers, compression contexts) stay out
///   of the heap. glibc raises its mmap threshold each time such a block is
///   freed, after which they come from the heap, fragment it and keep
///   resident memory creeping up over hours of recording (measured: +1.5 MB
///   in 8 simulated hours without this, +0.2 MB with it; `bench-recorder`).
///   A fixed threshold returns every block above 128 KiB to the system
///   when freed.
/// - **Batch** (`fit`, `replay`, `simulate`, the studies and the other
///   benches): the opposite. A fit allocates and frees series-sized blocks
///   (a prediction, a residual vector, a Jacobian) thousands of times; each
///   mapped, zeroed by the kernel and unmapped again spent 40 % of
///   `--fit auto`'s wall time on EMPS in the kernel (measured: 135 s, 75 s
///   of it system time; with these settings 78 s and 0.4 s). Blocks up to
///   32 MiB come from the heap, and the heap keeps up to 1 GiB of free top
///   instead of returning it at once; the process gives it all back when it
///   ends.
fn tune_malloc(command: &cli::args::Command) {
    use cli::args::Command as C;
    let long_running = matches!(
        command,
        C::Run { .. } | C::Soak { .. } | C::BenchLatency { .. } | C::BenchRecorder { .. }
    );
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only changes allocator tuning; it takes the arenas' locks.
    unsafe {
        if long_running {
            libc::mallopt(libc::M_MMAP_THRESHOLD, 128 * 1024);
        } else {
            libc::mallopt(libc::M_MMAP_THRESHOLD, 32 * 1024 * 1024);
            libc::mallopt(libc::M_TRIM_THRESHOLD, 1024 * 1024 * 1024);
            libc::mallopt(libc::M_TOP_PAD, 64 * 1024 * 1024);
        }
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    let _ = long_running;
}

fn main() {
    // `--ros-args ... [--]` sections are rcl's, not clap's: split them off.
    let argv: Vec<String> = std::env::args().collect();
    let (rest, ros_tokens) = friction_node::config::ros_args::split(&argv[1..]);
    let ros = match ros_tokens
        .as_deref()
        .map(|t| friction_node::config::RosArgs::parse(t, friction_node::config::DEFAULT_NODE_NAME))
        .transpose()
    {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(2);
        }
    };
    cli::logging::init(ros.as_ref());
    let cli = match cli::args::parse(std::iter::once(argv[0].clone()).chain(rest)) {
        Ok(c) => c,
        Err(e) => match e.kind() {
            clap::error::ErrorKind::DisplayHelp
            | clap::error::ErrorKind::DisplayVersion
            | clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => e.exit(),
            _ => {
                eprintln!("{}", cli::args::one_line_error(&e));
                std::process::exit(2);
            }
        },
    };
    tune_malloc(&cli.command);
    let allocations = || ALLOCATIONS.with(Cell::get);
    let result = cli::dispatch(cli, ros, &allocations);
    let stop = friction_node::interrupt::Stop::process();
    if result.is_ok() {
        // A stop in the last moments (writing the outputs) still ends the
        // command as the signal asked.
        let code = stop.exit_code_on_success();
        if code != 0 {
            eprintln!("{}", stop.check().unwrap_err());
            std::process::exit(code);
        }
    }
    if let Err(e) = result {
        // Whatever error the stop surfaced as, an interrupted command exits
        // as the signal asked.
        if let Err(i) = friction_node::interrupt::Stop::process().check() {
            eprintln!("{i}");
            std::process::exit(i.exit_code());
        }
        eprintln!("error: {e:#}");
        std::process::exit(2);
    }
}
