fn main() {
    let oc = std::env::args().nth(1).as_deref() != Some("nooc");
    let mut q = kanren::Query::new();
    q.set_occurs_check(oc);
    let hs = q.var("hs");
    let mut r = q.run(kanren::classic::zebrao(hs), kanren::RunConfig::default());
    let n = r.by_ref().count();
    println!("{n} answers, {} steps", r.steps());
}
