fn main() {
    std::process::exit(cotui::cli::run());
}
