fn main() {
    // Like other Unix filters, stop quietly when the reader of our output goes away
    // (`cotui decode big.log | head`) instead of failing on every later write.
    // SAFETY: setting a signal disposition to SIG_DFL before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    std::process::exit(cotui::cli::run().code());
}
