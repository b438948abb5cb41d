fn main() {
    let mut v: Vec<_> = std::fs::read_dir("meshes/corrupt").unwrap().map(|e| e.unwrap().path()).collect();
    v.sort();
    for p in v {
        let n = p.file_name().unwrap().to_string_lossy().to_string();
        let r = if n.starts_with("legacy") { zoovr::io::legacy::read(&p).map(|_| ()) } else if n.ends_with(".q") { Ok(()) } else { zoovr::io::plot3d::read(&p, None).map(|_| ()) };
        println!("{:?}", r.err().map(|e| e.to_string()));
    }
}
