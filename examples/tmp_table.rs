use specvar::spectrum::nufft::choice::Choice;
fn main() {
    for k in [8usize, 40, 320] {
        for s in [1.25, 1.5, 2.0] {
            let mut line = format!("K={k} σ={s}:");
            for w in 2..=16 {
                let c = Choice::with_width(1, k, s, w);
                line += &format!(" {w}:{:.1}", c.error.log10());
            }
            println!("{line}");
        }
    }
    let t = std::time::Instant::now();
    let c = Choice::cheapest(2, 320, 4096, 1e-9).unwrap();
    println!("{:?} {:?}", c, t.elapsed());
}
