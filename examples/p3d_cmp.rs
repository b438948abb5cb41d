use zoovr::field::ArrayData;
fn f32s(m: &zoovr::mesh::Mesh, n: &str) -> Vec<f32> {
    match &m.point_data.iter().find(|a| a.name == n).unwrap().data { ArrayData::F32(v) => v.clone(), _ => panic!() }
}
fn main() {
    let d = std::path::Path::new("/work/shared/data/bluntfin");
    let p = zoovr::io::plot3d::read(&d.join("bluntfinxyz.bin"), Some(&d.join("bluntfinq.bin"))).unwrap();
    let l = zoovr::io::legacy::read(&d.join("bluntfin_converted_legacy42_binary.vtk")).unwrap();
    println!("points equal: {}", p.points == l.points);
    for n in ["Density", "Momentum", "StagnationEnergy", "VelocityMagnitude", "Pressure"] {
        let a = f32s(&p, n); let b = f32s(&l, n);
        let diff = a.iter().zip(&b).filter(|(x, y)| x.to_bits() != y.to_bits()).count();
        println!("{n}: {} vs {} mismatches {diff}", a.len(), b.len());
    }
    // f32 arithmetic variant
    let rho = f32s(&p, "Density"); let m = f32s(&p, "Momentum"); let e = f32s(&p, "StagnationEnergy");
    let pl = f32s(&l, "Pressure"); let vl = f32s(&l, "VelocityMagnitude");
    let (mut dp, mut dv) = (0, 0);
    for i in 0..rho.len() {
        let d = if rho[i] != 0.0 { rho[i] } else { 1.0 };
        let rr = 1.0f32 / d;
        let (u, v, w) = (m[3*i] * rr, m[3*i+1] * rr, m[3*i+2] * rr);
        let v2 = u*u + v*v + w*w;
        let pp = (1.4f32 - 1.0) * (e[i] - 0.5 * d * v2);
        if pp.to_bits() != pl[i].to_bits() { dp += 1; }
        if v2.sqrt().to_bits() != vl[i].to_bits() { dv += 1; }
    }
    println!("f32 arithmetic: pressure mismatches {dp}, vmag {dv}");
    let g32 = 1.4f32 as f64;
    let variants: Vec<(&str, Box<dyn Fn(f64, [f64;3], f64) -> f64>)> = vec![
        ("std", Box::new(|d, m, e| { let rr = 1.0/d; let (u,v,w)=(m[0]*rr,m[1]*rr,m[2]*rr); 0.4*(e-0.5*d*(u*u+v*v+w*w)) })),
        ("gamma-1 computed", Box::new(|d, m, e| { let rr = 1.0/d; let (u,v,w)=(m[0]*rr,m[1]*rr,m[2]*rr); (1.4-1.0)*(e-0.5*d*(u*u+v*v+w*w)) })),
        ("g32", Box::new(move |d, m, e| { let rr = 1.0/d; let (u,v,w)=(m[0]*rr,m[1]*rr,m[2]*rr); (g32-1.0)*(e-0.5*d*(u*u+v*v+w*w)) })),
        ("m2/d", Box::new(|d, m, e| { (1.4-1.0)*(e-0.5*(m[0]*m[0]+m[1]*m[1]+m[2]*m[2])/d) })),
        ("g32 m2/d", Box::new(move |d, m, e| { (g32-1.0)*(e-0.5*(m[0]*m[0]+m[1]*m[1]+m[2]*m[2])/d) })),
        ("divide", Box::new(|d, m, e| { let (u,v,w)=(m[0]/d,m[1]/d,m[2]/d); (1.4-1.0)*(e-0.5*d*(u*u+v*v+w*w)) })),
    ];
    for (name, f) in &variants {
        let mut bad = 0;
        for i in 0..rho.len() {
            let r = f(rho[i] as f64, [m[3*i] as f64, m[3*i+1] as f64, m[3*i+2] as f64], e[i] as f64) as f32;
            if r.to_bits() != pl[i].to_bits() { bad += 1; }
        }
        println!("{name}: {bad}");
    }
}
