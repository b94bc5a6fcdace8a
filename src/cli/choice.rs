//! Value parsers for the library's named choices (collision method, response, tree builder, camera
//! view): `--help` lists the names, and a wrong name is refused with the list.

use clap::builder::{PossibleValuesParser, TypedValueParser};

/// A parser accepting the names of `all` (`name` gives each one's name).
pub fn named<T: Copy + Send + Sync + 'static>(
    all: &[T],
    name: fn(T) -> &'static str,
) -> impl TypedValueParser<Value = T> {
    let values: Vec<(&'static str, T)> = all.iter().map(|v| (name(*v), *v)).collect();
    let names: Vec<&'static str> = values.iter().map(|(n, _)| *n).collect();
    PossibleValuesParser::new(names).try_map(move |s: String| {
        // The names were checked by the possible-values parser before this runs.
        values
            .iter()
            .find(|(n, _)| *n == s)
            .map(|(_, v)| *v)
            .ok_or_else(|| format!("'{s}' is not one of the choices"))
    })
}

/// `--algorithm`: the narrow-phase method.
pub fn method() -> impl TypedValueParser<Value = orthosim::collision::Method> {
    use orthosim::collision::Method;
    named(&Method::ALL, Method::name)
}

/// `--response`: the collision response.
pub fn response() -> impl TypedValueParser<Value = orthosim::movement::Response> {
    use orthosim::movement::Response;
    named(&Response::ALL, Response::name)
}

/// `--model`: the movement model.
pub fn model() -> impl TypedValueParser<Value = orthosim::movement::MovementModel> {
    use orthosim::movement::MovementModel;
    named(&MovementModel::ALL, MovementModel::name)
}

/// `--tree`, `--method`: the sphere-tree builder.
pub fn tree_method() -> impl TypedValueParser<Value = orthosim::sphere_tree::TreeMethod> {
    use orthosim::sphere_tree::TreeMethod;
    named(&TreeMethod::ALL, TreeMethod::name)
}

/// `--camera`, `--view`: a standard clinical view.
#[cfg(feature = "viewer")]
pub fn camera() -> impl TypedValueParser<Value = orthosim::occlusion_view::CameraPreset> {
    use orthosim::occlusion_view::CameraPreset;
    named(&CameraPreset::ALL, CameraPreset::name)
}
