use gmwm::fit::Gmwm;
use gmwm::fit::StartInputs;
use gmwm::imu::read_wv_json;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let file = &args[1];
    let col = &args[2];
    let model = &args[3];
    let series = read_wv_json(std::path::Path::new(file), None).unwrap();
    let wv = &series.iter().find(|(n, _)| n == col).unwrap().1;
    let fit = Gmwm::parse(model)
        .unwrap()
        .fit_from_wv(wv, StartInputs::from_wv(wv))
        .unwrap();
    println!("{fit}");
    let c = fit.canonical().unwrap();
    println!("{c}");
    println!(
        "separation {} objective {} vs {}",
        c.separation, c.objective, fit.objective
    );
}
